// Study files: the schema's defaults as documented, sections that must be mappings, and the
// identification solver a study names actually running in its trials.
#include "lrcal/study/study.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "lrcal/core/data_dir.h"
#include "lrcal/core/error.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/design/experiment_design.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/identification.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/study/trial_store.h"
#include "study/trial_pipeline.h"
#include "test_util.h"

namespace lrcal {
namespace {

// Every default in StudyDefaults() must appear, with the same value, in the first YAML block of
// docs/STUDIES.md (which says "Defaults are those shown").
void ExpectDocumented(const Json& defaults, const YAML::Node& doc, const std::string& path) {
  for (auto it = defaults.begin(); it != defaults.end(); ++it) {
    const std::string key = path.empty() ? it.key() : path + "." + it.key();
    const YAML::Node node = doc[it.key()];
    ASSERT_TRUE(node.IsDefined()) << "docs/STUDIES.md does not show '" << key << "'";
    const Json& value = it.value();
    if (value.is_object()) {
      ExpectDocumented(value, node, key);
    } else if (value.is_null()) {
      EXPECT_TRUE(node.IsNull()) << key;
    } else if (value.is_array()) {
      EXPECT_TRUE(node.IsSequence() && node.size() == value.size()) << key;
    } else if (value.is_string()) {
      EXPECT_EQ(node.Scalar(), value.get<std::string>()) << key;
    } else if (value.is_boolean()) {
      EXPECT_EQ(node.Scalar(), value.get<bool>() ? "true" : "false") << key;
    } else {
      EXPECT_DOUBLE_EQ(std::stod(node.Scalar()), value.get<double>()) << key;
    }
  }
}

TEST(StudySchema, DocumentedDefaultsAreTheSchemasDefaults) {
  std::ifstream in(testing::SourcePath("docs/STUDIES.md"));
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  const auto begin = text.find("```yaml\n");
  ASSERT_NE(begin, std::string::npos);
  const auto end = text.find("```", begin + 8);
  const YAML::Node doc = YAML::Load(text.substr(begin + 8, end - begin - 8));
  ExpectDocumented(StudyDefaults(), doc, "");
}

// The study's defaults of the option structs' settings are the structs' own (settings.h): one
// default per knob, whichever front end reads it.
template <class Options>
void ExpectStudyDefaults(const std::vector<SettingField<Options>>& fields,
                         const std::vector<std::string>& names) {
  for (const std::string& name : names) {
    const SettingField<Options>& f = *FindSetting(fields, name);
    const std::string key = f.spec.Spelling(Frontend::kStudyFile);
    const Json* j = &StudyDefaults();
    for (std::size_t at = 0, dot = 0; dot != std::string::npos; at = dot + 1) {
      dot = key.find('.', at);
      j = &(*j)[key.substr(at, dot == std::string::npos ? dot : dot - at)];
    }
    EXPECT_EQ(j->get<double>(), f.Default()) << key;
  }
}

TEST(StudySchema, StudyDefaultsAreTheOptionStructsOwn) {
  ExpectStudyDefaults(NoiseModel::Settings(), {"sigma_mm", "repetitions", "encoder_sigma_mrad",
                                               "form_sigma_mm", "outlier_fraction"});
  ExpectStudyDefaults(IdentificationOptions::Settings(), {"max_iterations"});
  ExpectStudyDefaults(SamplingOptions::Settings(), {"min_singular_value"});
  ExpectStudyDefaults(SelectionOptions::Settings(), {"samples", "restarts"});
  ExpectStudyDefaults(TruthOptions::Settings(), {"scale", "angle_sigma_mrad", "length_sigma_mm"});
}

// The truth's settings are checked where they are written, in the study's words.
TEST(StudySchema, TheTruthsSettingsAreCheckedAtTheirLine) {
  const std::string dir = testing::TempDir("study_truth");
  const auto refused = [&](const std::string& truth) {
    std::ofstream(dir + "/s.yaml") << "name: s\nseed: 1\ntrials: 2\ntruth: " << truth << "\n";
    try {
      LoadStudy(dir + "/s.yaml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  using ::testing::AllOf;
  using ::testing::HasSubstr;
  EXPECT_THAT(refused("{scale: -1}"), AllOf(HasSubstr("s.yaml:4 key 'truth.scale'"),
                                            HasSubstr("expected a finite value >= 0")));
  EXPECT_THAT(refused("{mode: random, angle_sigma_mrad: -0.1}"),
              AllOf(HasSubstr("truth.angle_sigma_mrad"), HasSubstr("(mrad)")));
  EXPECT_THAT(refused("{ranger_scale_ppm: 600000}"),
              AllOf(HasSubstr("truth.ranger_scale_ppm"), HasSubstr("below 500,000")));
  EXPECT_EQ(refused("{mode: random, angle_sigma_mrad: 0.5}"), "accepted");
}

// Every study shipped in studies/ loads (the README and docs run them by name).
TEST(StudySchema, EveryShippedStudyLoads) {
  int count = 0;
  for (const auto& e : std::filesystem::directory_iterator(testing::SourcePath("studies"))) {
    if (e.path().extension() != ".yaml") continue;
    SCOPED_TRACE(e.path().string());
    EXPECT_NO_THROW({
      const Study study = LoadStudy(e.path().string());
      EXPECT_FALSE(study.cells.empty());
    });
    ++count;
  }
  EXPECT_GE(count, 14);
}

std::string WriteStudy(const std::string& name, const std::string& body) {
  const std::string path = testing::TempDir("study_" + name) + "/s.yaml";
  std::ofstream(path) << "name: s\nseed: 1\ntrials: 3\nrobot: "
                      << testing::SourcePath("studies/robots/paper.yaml") << "\n"
                      << body;
  return path;
}

std::string LoadError(const std::string& name, const std::string& body) {
  try {
    LoadStudy(WriteStudy(name, body));
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(StudySchema, SectionsGivenAsNothingOrScalarsAreErrorsNamingTheKey) {
  const std::string empty = LoadError("null_section", "noise:\npool: {size: 60}\n");
  EXPECT_THAT(empty, ::testing::HasSubstr("s.yaml:5 key 'noise'")) << empty;
  EXPECT_THAT(empty, ::testing::HasSubstr(
                         "expected a mapping with keys average, encoder_sigma_mrad, form_sigma_mm, "
                         "outlier_fraction, outlier_sigma_mm, repetitions, sigma_mm, got nothing"))
      << empty;
  const std::string scalar = LoadError("scalar_section", "selection: 5\n");
  EXPECT_THAT(scalar, ::testing::HasSubstr("key 'selection'")) << scalar;
  EXPECT_THAT(scalar, ::testing::HasSubstr("got 5")) << scalar;
  const std::string solver = LoadError("bad_solver", "identification: {solver: gauss}\n");
  EXPECT_THAT(solver, ::testing::HasSubstr("unknown solver 'gauss'; expected lm or ceres"))
      << solver;
}

// identification.solver: ceres changes the cell and runs Ceres in every trial; both solvers
// reach the same least-squares minimum (to ~1e-9 of the parameters).
TEST(StudySchema, CeresSolverRunsInTheTrialsAndAgreesWithLm) {
  const std::string common = "pool: {size: 40}\nselection: {count: 35}\nvalidation: {size: 5}\n";
  const Study lm = LoadStudy(WriteStudy("lm", common + "identification: {solver: lm}\n"));
  const Study ceres = LoadStudy(WriteStudy("ceres", common + "identification: {solver: ceres}\n"));
  EXPECT_NE(lm.cells[0].id, ceres.cells[0].id);
  ASSERT_EQ(ceres.cells[0].typed.identification.solver, IdentificationOptions::Solver::kCeres);
  const auto lm_cell = PrepareCell(lm, lm.cells[0]);
  const auto ceres_cell = PrepareCell(ceres, ceres.cells[0]);
  TrialWorkspace ws;
  for (long long trial = 0; trial < 3; ++trial) {
    const TrialRecord a = RunTrial(*lm_cell, trial, &ws);
    const TrialRecord b = RunTrial(*ceres_cell, trial, &ws);
    ASSERT_EQ(a.status, TrialStatus::kOk);
    ASSERT_EQ(b.status, TrialStatus::kOk);
    ASSERT_EQ(a.errors.size(), b.errors.size());
    bool identical = true;
    for (std::size_t k = 0; k < a.errors.size(); ++k) {
      EXPECT_NEAR(a.errors[k], b.errors[k], 1e-9) << lm_cell->parameter_names[k];
      identical &= a.errors[k] == b.errors[k];
    }
    EXPECT_FALSE(identical) << "the Ceres cell gave LM's bits: is the solver key ignored?";
  }
}

// A relative robot path in a study file is taken relative to the study file's folder, whatever
// the working directory.
TEST(StudySchema, RelativeRobotPathsResolveAgainstTheStudyFolder) {
  const std::string dir = testing::TempDir("study_relative_robot");
  std::filesystem::create_directories(dir + "/rigs");
  std::filesystem::copy_file(testing::SourcePath("studies/robots/paper.yaml"),
                             dir + "/rigs/arm.yaml");
  std::ofstream(dir + "/s.yaml") << "name: s\nseed: 1\ntrials: 2\nrobot: rigs/arm.yaml\n"
                                    "pool: {size: 40}\nselection: {count: 30}\n";
  const Study study = LoadStudy(dir + "/s.yaml");
  EXPECT_EQ(study.folder(), dir);
  const auto cell = PrepareCell(study, study.cells[0]);
  EXPECT_EQ(cell->robot->source, dir + "/rigs/arm.yaml");
}

// A cell's identity (id, pool, validation set, prediction draws) counts files by content: the
// same study in two folders, its robot and configuration files named by relative or absolute
// paths, is the same cells with the same numbers; a changed file is another cell.
TEST(StudySchema, CellsAreTheSameWhereverTheStudyAndItsFilesAre) {
  const std::string paper = testing::SourcePath("studies/robots/paper.yaml");
  const auto write = [&](const std::string& dir, const std::string& robot) {
    std::filesystem::create_directories(dir + "/rigs");
    std::filesystem::copy_file(paper, dir + "/rigs/arm.yaml",
                               std::filesystem::copy_options::overwrite_existing);
    testing::WritePaperConfigurationFiles(dir + "/rigs", 60, 12, 3, 4);
    std::ofstream(dir + "/s.yaml") << "name: s\nseed: 1\ntrials: 2\nrobot: " << robot
                                   << "\npool: {file: rigs/pool.csv}\n"
                                      "validation: {file: rigs/val.csv}\n"
                                      "selection: {count: 30}\n";
    return LoadStudy(dir + "/s.yaml");
  };
  const std::string a = testing::TempDir("identity_a"), b = testing::TempDir("identity_b/x");
  const Study sa = write(a, "rigs/arm.yaml");
  const Study sb = write(b, b + "/rigs/arm.yaml");
  ASSERT_EQ(sa.cells[0].id, sb.cells[0].id);
  const auto ca = PrepareCell(sa, sa.cells[0]), cb = PrepareCell(sb, sb.cells[0]);
  EXPECT_EQ(ca->validation_stream, cb->validation_stream);
  for (int k = 0; k < 12; ++k) EXPECT_EQ(ca->predicted_validation[k], cb->predicted_validation[k]);
  // Another validation file is another cell.
  testing::WritePaperConfigurationFiles(b + "/rigs", 60, 12, 3, 5);
  EXPECT_NE(LoadStudy(b + "/s.yaml").cells[0].id, sa.cells[0].id);
  // A sweep over two robot files: each cell hashes its own file.
  std::string text;
  {
    std::ifstream in(paper);
    std::stringstream ss;
    ss << in.rdbuf();
    text = ss.str();
  }
  std::ofstream(a + "/rigs/arm2.yaml") << text << "\n# another file\n";
  std::ofstream(a + "/sweep.yaml")
      << "name: s\nseed: 1\ntrials: 2\nrobot: rigs/arm.yaml\npool: {size: 40}\n"
         "selection: {count: 30}\nsweep:\n  axes:\n    - {key: robot, values: [rigs/arm.yaml, "
         "rigs/arm2.yaml]}\n";
  const Study sweep = LoadStudy(a + "/sweep.yaml");
  ASSERT_EQ(sweep.cells.size(), 2u);
  EXPECT_NE(sweep.cells[0].settings["robot_file_fnv1a"],
            sweep.cells[1].settings["robot_file_fnv1a"]);
}

// identification.loss: the scale is in units of one reading's σ; a study that does not use a
// loss keeps the cell names it had before the key existed (loss: none makes loss_scale moot).
TEST(StudySchema, RobustLossScaleIsInSigmaAndLeavesOldCellsAlone) {
  const std::string dir = testing::TempDir("study_loss");
  const auto load = [&](const std::string& identification) {
    std::ofstream(dir + "/s.yaml") << "name: s\nseed: 1\ntrials: 2\nnoise: {sigma_mm: 0.2}\n"
                                      "identification: "
                                   << identification << "\n";
    return LoadStudy(dir + "/s.yaml");
  };
  const Study plain = load("{}");
  const Study moot = load("{loss: none, loss_scale: 3}");
  const Study huber = load("{loss: huber}");
  EXPECT_EQ(plain.cells[0].id, moot.cells[0].id);
  EXPECT_NE(plain.cells[0].id, huber.cells[0].id);
  EXPECT_EQ(huber.cells[0].typed.identification.loss, RobustLoss::kHuber);
  EXPECT_DOUBLE_EQ(huber.cells[0].typed.identification.loss_scale, 1.345 * 0.2e-3);
  EXPECT_NE(load("{loss: cauchy, loss_scale: 2}").cells[0].id,
            load("{loss: cauchy, loss_scale: 3}").cells[0].id);
  std::ofstream(dir + "/bad.yaml") << "name: s\nseed: 1\ntrials: 2\nnoise: {sigma_mm: 0}\n"
                                      "identification: {loss: huber}\n";
  try {
    LoadStudy(dir + "/bad.yaml");
    ADD_FAILURE() << "a loss without noise was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr("identification.loss")) << e.what();
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr("sigma_mm")) << e.what();
  }
  std::ofstream(dir + "/bad.yaml") << "name: s\nseed: 1\ntrials: 2\n"
                                      "identification: {loss: huber, loss_scale: -1}\n";
  EXPECT_THROW(LoadStudy(dir + "/bad.yaml"), InputError);
}

// The loss scale one way per cell, its unit in its name: loss_scale_sigma (multiples of σ; the
// earlier spelling loss_scale reads as it, and a cell's name is what it was before the rename)
// or loss_scale_mm (mm; no σ needed). A mapping that gives both is refused at its line.
TEST(StudySchema, TheLossScaleIsGivenInMillimetresOrInSigmas) {
  using ::testing::AllOf;
  using ::testing::HasSubstr;
  const std::string dir = testing::TempDir("study_loss_units");
  const auto load = [&](const std::string& noise, const std::string& identification,
                        const std::string& extra = "") {
    std::ofstream(dir + "/s.yaml") << "name: s\nseed: 1\ntrials: 2\nnoise: " << noise
                                   << "\nidentification: " << identification << "\n"
                                   << extra;
    return LoadStudy(dir + "/s.yaml");
  };
  const Study earlier = load("{sigma_mm: 0.2}", "{loss: cauchy, loss_scale: 2.385}");
  const Study sigmas = load("{sigma_mm: 0.2}", "{loss: cauchy, loss_scale_sigma: 2.385}");
  EXPECT_EQ(earlier.cells[0].id, sigmas.cells[0].id);
  EXPECT_EQ(earlier.cells[0].settings["identification"]["loss_scale_sigma"], 2.385);
  EXPECT_FALSE(earlier.cells[0].settings["identification"].contains("loss_scale"));
  const Json identity = CellIdentity(sigmas.cells[0].settings);
  EXPECT_EQ(identity["identification"]["loss_scale"], 2.385);
  EXPECT_FALSE(identity["identification"].contains("loss_scale_sigma"));
  EXPECT_DOUBLE_EQ(sigmas.cells[0].typed.identification.loss_scale, 2.385 * 0.2e-3);

  // In mm: the default σ multiple leaves the cell; no noise is needed.
  const Study mm = load("{sigma_mm: 0}", "{loss: huber, loss_scale_mm: 0.27}");
  EXPECT_DOUBLE_EQ(mm.cells[0].typed.identification.loss_scale, 0.27e-3);
  EXPECT_FALSE(mm.cells[0].settings["identification"].contains("loss_scale_sigma"));
  EXPECT_NE(mm.cells[0].id, load("{sigma_mm: 0}", "{loss: huber, loss_scale_mm: 0.3}").cells[0].id);
  // Without a loss neither spelling changes the cell's name.
  EXPECT_EQ(load("{sigma_mm: 0.2}", "{loss_scale_mm: 0.3}").cells[0].id,
            load("{sigma_mm: 0.2}", "{}").cells[0].id);

  // A sweep in either spelling (the earlier one too) over the base's other one.
  const Study swept =
      load("{sigma_mm: 0.2}", "{loss: huber, loss_scale_mm: 0.3}",
           "sweep:\n  axes:\n    - {key: identification.loss_scale, values: [1, 2]}\n");
  ASSERT_EQ(swept.cells.size(), 2u);
  EXPECT_EQ(swept.axis_keys[0], "identification.loss_scale_sigma");
  EXPECT_DOUBLE_EQ(swept.cells[1].typed.identification.loss_scale, 2 * 0.2e-3);
  EXPECT_FALSE(swept.cells[1].settings["identification"].contains("loss_scale_mm"));
  const Study swept_mm =
      load("{sigma_mm: 0.2}", "{loss: huber}",
           "sweep:\n  axes:\n    - {key: ., values: [{identification: {loss_scale_mm: 0.5}}]}\n");
  EXPECT_DOUBLE_EQ(swept_mm.cells[0].typed.identification.loss_scale, 0.5e-3);
  EXPECT_FALSE(swept_mm.cells[0].settings["identification"].contains("loss_scale_sigma"));

  const auto refused = [&](const std::string& noise, const std::string& identification) {
    try {
      load(noise, identification);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_THAT(
      refused("{sigma_mm: 0.2}", "{loss: huber, loss_scale_sigma: 1, loss_scale_mm: 1}"),
      AllOf(HasSubstr("s.yaml:5 key 'identification.loss_scale_mm'"), HasSubstr("given twice")));
  EXPECT_THAT(refused("{sigma_mm: 0.2}", "{loss: huber, loss_scale: 1, loss_scale_sigma: 1}"),
              HasSubstr("given twice"));
  EXPECT_THAT(refused("{sigma_mm: 0.2}", "{loss: huber, loss_scale_mm: -1}"),
              AllOf(HasSubstr("identification.loss_scale_mm"), HasSubstr("(mm), got -1")));
  // Two axes of one cell, one spelling each: refused, naming both values' lines.
  try {
    load("{sigma_mm: 0.2}", "{loss: huber}",
         "sweep:\n  combine: product\n  axes:\n"
         "    - {key: identification.loss_scale_mm, values: [0.3]}\n"
         "    - {key: identification.loss_scale_sigma, values: [2]}\n");
    ADD_FAILURE() << "two spellings from two axes were accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("s.yaml:10"), HasSubstr("twice"),
                                HasSubstr("at line 9 (identification.loss_scale_mm)"),
                                HasSubstr("at line 10 (identification.loss_scale_sigma)")));
  }
}

// noise.average: the mean leaves earlier cells alone; a median is its own cell, and with gross
// errors in the readings its calibrations are far better than the mean's, with the predicted
// accuracy (from the median's weights) still matching what the trials show.
TEST(StudySchema, TheMedianOfTheReadingsIsASettingAndResistsOutliers) {
  const std::string dir = testing::TempDir("study_average");
  const auto write = [&](const std::string& noise, const std::string& extra = "") {
    std::ofstream(dir + "/s.yaml")
        << "name: s\nseed: 3\ntrials: 30\nnoise: " << noise << "\nselection: {method: backward}\n"
        << extra;
    return dir + "/s.yaml";
  };
  const std::string plain = LoadStudy(write("{sigma_mm: 0.05}")).cells[0].id;
  EXPECT_EQ(LoadStudy(write("{sigma_mm: 0.05, average: mean}")).cells[0].id, plain);
  const Study median = LoadStudy(write("{sigma_mm: 0.05, average: median}"));
  EXPECT_NE(median.cells[0].id, plain);
  EXPECT_EQ(median.cells[0].typed.noise.average.kind, Averaging::Kind::kMedian);
  const std::string study =
      write("{sigma_mm: 0.05, repetitions: 5, outlier_fraction: 0.05}",
            "sweep:\n  axes:\n    - key: noise.average\n      values: [mean, median]\n");
  testing::RunStudyFile(study, dir + "/run", 2);
  const Json summary = Json::parse(testing::ReadFile(dir + "/run/tables/summary.json"));
  ASSERT_EQ(summary["cells"].size(), 2u);
  const Json& mean_cell = summary["cells"][0]["validation"]["rms_pos_x"];
  const Json& median_cell = summary["cells"][1]["validation"]["rms_pos_x"];
  EXPECT_EQ(summary["cells"][1]["settings"]["noise"]["average"], "median");
  EXPECT_LT(median_cell["mean"].get<double>() * 3, mean_cell["mean"].get<double>());
  // The median's prediction (weights R/c) against its trials: within 4 standard errors and 10 %.
  const double predicted = median_cell["mean_predicted"].get<double>();
  EXPECT_NEAR(median_cell["mean"].get<double>(), predicted,
              4 * median_cell["mean_se"].get<double>() + 0.1 * predicted);
}

TEST(DataDirectory, LrcalDataDirOverridesAndIsChecked) {
  ::setenv("LRCAL_DATA_DIR", testing::SourcePath("").c_str(), 1);
  EXPECT_EQ(FindDataFile("studies/robots/paper.yaml"),
            testing::SourcePath("studies/robots/paper.yaml"));
  ::setenv("LRCAL_DATA_DIR", "/nonexistent/lrcal", 1);
  try {
    DataDirectory();
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()),
                ::testing::HasSubstr("LRCAL_DATA_DIR: '/nonexistent/lrcal' is not an lrcal "
                                     "data folder"))
        << e.what();
  }
  ::unsetenv("LRCAL_DATA_DIR");
}

TEST(DataDirectory, AnEmbeddingProgramsFolderComesBeforeTheProgramsOwn) {
  // The test binary's folder has data next to it (build/share/lrcal, which has no x.yaml): the
  // registered folder is searched first, and $LRCAL_DATA_DIR still comes before it.
  const std::string dir = testing::TempDir("embedded_data");
  std::filesystem::create_directories(dir + "/studies/robots");
  std::ofstream(dir + "/studies/robots/x.yaml") << "x";
  SetEmbeddedDataDirectory(dir);
  EXPECT_EQ(FindDataFile("studies/robots/x.yaml"), dir + "/studies/robots/x.yaml");
  ::setenv("LRCAL_DATA_DIR", testing::SourcePath("").c_str(), 1);
  EXPECT_EQ(FindDataFile("studies/robots/x.yaml"), "");
  ::unsetenv("LRCAL_DATA_DIR");
  SetEmbeddedDataDirectory("");
  EXPECT_EQ(FindDataFile("studies/robots/x.yaml"), "");
}

TEST(StudyPath, AFolderNamedLikeAShippedStudyDoesNotHideIt) {
  // `lrcal run quick --out quick`, run again from the same folder: 'quick' is now a run
  // directory, and still means the shipped study (likewise a robot name).
  const std::string dir = testing::TempDir("study_path_folder");
  std::filesystem::create_directories(dir + "/quick");
  std::filesystem::create_directories(dir + "/paper");
  const std::filesystem::path before = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  const std::string study = ResolveStudyPath("quick");
  const std::string robot = ResolveRobotPath("paper");
  std::filesystem::current_path(before);
  EXPECT_EQ(study, FindDataFile("studies/quick.yaml"));
  EXPECT_EQ(robot, FindDataFile("studies/robots/paper.yaml"));
  EXPECT_FALSE(study.empty());
}

TEST(CellPrediction, AtTheTruthIsTheNominalFormulaForAnArmWhoseNominalIsTheTruth) {
  // Independent path: an arm whose nominal link values are the true ones, evaluated at e = 0,
  // has the Jacobian of the original arm at e = truth.
  const std::string dir = testing::TempDir("prediction_truth");
  std::ofstream(dir + "/s.yaml") << "name: p\nseed: 2\ntrials: 5\nrobot: "
                                 << testing::SourcePath("studies/robots/paper.yaml")
                                 << "\npool: {size: 40}\nselection: {count: 30}\n"
                                    "validation: {size: 5}\n";
  const Study study = LoadStudy(dir + "/s.yaml");
  const auto cell = PrepareCell(study, study.cells[0]);
  const RobotModel& robot = *cell->robot;
  std::vector<Link> links = robot.links();
  for (int i = 0; i < robot.num_links(); ++i)
    for (int v = 0; v < kValuesPerLink; ++v)
      links[i].nominal[v] = robot.nominal_values()[kValuesPerLink * i + v] +
                            cell->file_true_errors[kValuesPerLink * i + v];
  const RobotModel at_truth("truth", links);
  const MeasurementModel model(at_truth, cell->planes, cell->model->parameters());
  const Eigen::MatrixXd G = IdentificationJacobian(model, cell->design.configs);
  const CellSettings& s = cell->cell->typed;
  const Eigen::VectorXd expected =
      ParameterCovariance(s.noise.repetitions * (G.transpose() * G), s.noise.sigma)
          .diagonal()
          .cwiseSqrt();
  ASSERT_EQ(cell->predicted_std_truth.size(), expected.size());
  for (Eigen::Index k = 0; k < expected.size(); ++k)
    EXPECT_NEAR(cell->predicted_std_truth[k] / expected[k], 1.0, 1e-9) << k;
  // It differs from the prediction at the nominal model (mrad-size true errors), and the store
  // keeps it.
  EXPECT_GT((cell->predicted_std_truth - cell->predicted_std).cwiseAbs().maxCoeff(), 0.0);
  TrialStore store(dir + "/store.sqlite");
  store.PutCell(ToStoredCell(*cell));
  EXPECT_EQ(store.Cells()[0].predicted_std_truth,
            std::vector<double>(cell->predicted_std_truth.data(),
                                cell->predicted_std_truth.data() + expected.size()));
}

}  // namespace
}  // namespace lrcal

namespace lrcal {
namespace {

// A URDF robot in a study: tool_link names the ranger's link (the example has a camera link
// beside it); without it the study is refused with a message that says what to add.
TEST(StudyUrdf, ToolLinkPicksTheRangerOfAUrdfRobot) {
  const std::string dir = testing::TempDir("study_urdf");
  const std::string base = "name: ur5\nseed: 3\ntrials: 4\nrobot: " +
                           testing::SourcePath("examples/urdf/ur5_ranger.urdf") +
                           "\nplane: {normal: [0, 0, 1], offset: 0}\npool: {size: 60}\n"
                           "selection: {count: 40}\nvalidation: {size: 10}\n"
                           "identification: {on_rank_deficient: fix}\n";
  std::ofstream(dir + "/with.yaml") << base << "tool_link: ranger\n";
  const RunResult r = testing::RunStudyFile(dir + "/with.yaml", dir + "/run", 2);
  EXPECT_TRUE(r.complete);
  std::ofstream(dir + "/without.yaml") << base;
  try {
    testing::RunStudyFile(dir + "/without.yaml", dir + "/run2", 2);
    ADD_FAILURE() << "no error without tool_link";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr("tool_link: NAME")) << e.what();
  }
  std::ofstream(dir + "/yaml.yaml") << "name: y\nseed: 3\ntrials: 4\ntool_link: ranger\n";
  try {
    LoadStudy(dir + "/yaml.yaml");
    ADD_FAILURE() << "no error for tool_link with a YAML robot";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr("key 'tool_link'")) << e.what();
  }
}

}  // namespace
}  // namespace lrcal
