#include "lrcal/paper/paper_case.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "lrcal/core/error.h"

namespace lrcal {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

const double kPaperIdentified[2][6][5] = {{{-7.8525, -2.4425, -2.1491, 0.5724, kNaN},
                                           {1.2119, 0.0553, 1.6291, kNaN, 1.1436},
                                           {0.0949, -1.5013, 1.3863, 0.2838, kNaN},
                                           {0.2936, 2.6439, 0.3531, 1.2179, kNaN},
                                           {-5.2130, -3.8485, -0.0797, 0.2895, kNaN},
                                           {0.5628, 0.5207, 0.8714, 0.7422, -3.7951}},
                                          {{-7.0607, -2.8193, -0.1191, 0.1555, kNaN},
                                           {0.8234, 0.2574, 1.6439, kNaN, 1.4527},
                                           {0.3428, -2.0967, 1.0172, -0.5597, kNaN},
                                           {0.5364, 2.2958, 0.0014, 1.4096, kNaN},
                                           {-5.6786, -4.2081, 0.3607, 0.6214, kNaN},
                                           {1.4004, 0.4974, 0.4545, 0.4274, -3.3556}}};

const double kPaperValidation[3][3][4] = {{{2.7612, 3.1491, 11.7347, 16.1688},
                                           {2.5917, 3.2196, 18.6857, 17.0006},
                                           {2.2119, 2.3480, 8.5899, 9.9512}},
                                          {{0.9921, 0.7003, 4.9654, 3.2981},
                                           {1.0148, 1.6199, 4.6951, 7.3035},
                                           {1.0524, 0.5910, 4.3151, 2.7741}},
                                          {{0.3427, 0.2273, 1.9067, 0.9378},
                                           {0.2974, 0.3374, 1.4779, 1.2271},
                                           {0.3785, 0.7671, 1.5664, 2.3669}}};

PaperCasesResult RunPaperCases(const RobotModel& robot, const Truth& true_arm, const Plane& plane,
                               const PaperCaseOptions& options) {
  PaperCasesResult result;
  result.true_errors = true_arm.LinkErrors(robot);
  const Eigen::VectorXd truth = true_arm.LinkValues(robot);
  SamplingOptions pool_options = options.sampling;
  pool_options.true_link_values = truth;  // the simulated readings must exist
  pool_options.true_planes = PlaneSet(plane);
  result.pool = SampleConfigurations(robot, plane, options.pool_size,
                                     RandomStream(options.seed, 0, 0, RandomPurpose::kPool),
                                     pool_options, &result.pool_report);
  SamplingOptions validation_options = options.sampling;
  validation_options.require_beam_hit = false;  // the whole workspace
  result.validation =
      SampleConfigurations(robot, plane, options.validation_size,
                           RandomStream(options.seed, 0, 0, RandomPurpose::kValidation),
                           validation_options, &result.validation_report);
  result.nominal_validation = ComparePoses(robot, truth, robot.nominal_values(), result.validation);

  MeasurementModel model(robot, plane, MakeParameterSet(robot, options.plane_terms));
  const Eigen::MatrixXd G = IdentificationJacobian(model, result.pool);
  const RandomStream noise(options.seed, 0, 0, RandomPurpose::kNoise);
  const int counts[2] = {options.case1_count, options.case2_count};
  const SelectionOptions* selections[2] = {&options.case1_selection, &options.case2_selection};
  for (int c = 0; c < 2; ++c) {
    PaperCase pc;
    pc.label = "case " + std::to_string(c + 1);
    pc.selection = SelectConfigurations(
        G, counts[c], *selections[c], RandomStream(options.seed, c, 0, RandomPurpose::kSelection));
    TargetedConfigurations chosen = result.pool.Subset(pc.selection.indices);
    SimulateReadings(robot, truth, plane, options.sampling.ranger, chosen, options.noise, noise,
                     &pc.data, nullptr, nullptr, &pc.selection.indices);
    IdentificationOptions id = options.identification;
    id.sigma = options.noise.sigma;
    pc.summary = Identify(model, pc.data, id);
    const Eigen::VectorXd identified = pc.summary.IsSolutionUsable()
                                           ? model.LinkValues(pc.summary.delta.data())
                                           : robot.nominal_values();
    pc.validation = ComparePoses(robot, truth, identified, result.validation);
    result.cases.push_back(std::move(pc));
  }
  return result;
}

PaperCasesResult RunPaperCases(const RobotFile& rig, PaperCaseOptions options) {
  if (!rig.planes || rig.planes->size() != 1)
    throw InputError(rig.path, "the robot file has " +
                                   std::to_string(rig.planes ? rig.planes->size() : 0) +
                                   " planes; the paper's study uses exactly one");
  options.sampling.ranger = rig.ranger;
  return RunPaperCases(rig.robot, rig.truth, (*rig.planes)[0], options);
}

Table PaperParameterTable(const RobotModel& robot, const PaperCasesResult& result) {
  Table t({"link", "parameter", "unit", "true", "case 1 (lrcal)", "case 1 (paper)",
           "case 2 (lrcal)", "case 2 (paper)"},
          "Identified parameter errors: lrcal's realisation beside the paper's (mrad, mm)");
  for (int k : robot.parameter_indices()) {
    const int link = k / kValuesPerLink, v = k % kValuesPerLink;
    const double unit = 1e3;  // rad → mrad, m → mm
    std::vector<std::string> row = {std::to_string(link + 1), robot.ValueName(k),
                                    IsAngle(v) ? "mrad" : "mm",
                                    Fixed(result.true_errors[k] * unit)};
    for (int c = 0; c < 2; ++c) {
      double ours = std::numeric_limits<double>::quiet_NaN();
      if (c < static_cast<int>(result.cases.size())) {
        const auto& s = result.cases[c].summary;
        for (std::size_t j = 0; j < s.names.size(); ++j)
          if (s.names[j] == robot.ValueName(k) && s.IsSolutionUsable()) ours = s.delta[j] * unit;
      }
      row.push_back(Fixed(ours));
      row.push_back(link < 6 && robot.num_links() == 6 ? Fixed(kPaperIdentified[c][link][v]) : "—");
    }
    t.AddRow(row);
  }
  return t;
}

Table PaperValidationTable(const PaperCasesResult& result) {
  Table t({"model", "axis", "RMS pos (mm)", "paper", "RMS ori (mrad)", "paper", "max pos (mm)",
           "paper", "max ori (mrad)", "paper"},
          "Validation errors over the validation configurations: lrcal beside the paper "
          "(mm, mrad)");
  const char* axes[3] = {"x", "y", "z"};
  for (int m = 0; m < 3; ++m) {
    const PoseErrorStats& s =
        m == 0 ? result.nominal_validation.stats : result.cases[m - 1].validation.stats;
    const std::string name = m == 0 ? "nominal" : result.cases[m - 1].label;
    for (int a = 0; a < 3; ++a) {
      t.AddRow({name, axes[a], Fixed(s.rms_position[a] * 1e3), Fixed(kPaperValidation[m][a][0]),
                Fixed(s.rms_orientation[a] * 1e3), Fixed(kPaperValidation[m][a][1]),
                Fixed(s.max_position[a] * 1e3), Fixed(kPaperValidation[m][a][2]),
                Fixed(s.max_orientation[a] * 1e3), Fixed(kPaperValidation[m][a][3])});
    }
  }
  return t;
}

ResultJson PaperCasesJson(const PaperCasesResult& r, const PaperCaseOptions& options) {
  ResultJson j;
  j["seed"] = options.seed;
  j["pool"] = r.pool_report.ToString();
  j["validation_sampling"] = r.validation_report.ToString();
  ResultJson cases = ResultJson::array();
  for (const auto& c : r.cases) {
    ResultJson cj;
    cj["label"] = c.label;
    cj["selected"] = c.selection.indices;
    cj["sigma_min"] = c.selection.score;
    cj["termination"] = TerminationName(c.summary.termination);
    cj["iterations"] = c.summary.iterations;
    cj["residual_rms"] = c.summary.residual_rms;
    ResultJson p = ResultJson::object();
    for (std::size_t k = 0; k < c.summary.names.size() && c.summary.IsSolutionUsable(); ++k)
      p[c.summary.names[k]] = c.summary.delta[k];
    cj["delta"] = p;
    ResultJson sd = ResultJson::object();
    for (std::size_t k = 0; k < c.summary.names.size() && c.summary.IsSolutionUsable(); ++k)
      sd[c.summary.names[k]] = c.summary.std_given[k];
    cj["std_given_sigma"] = sd;
    cj["validation_rms_position"] = lrcal::ToJson(Eigen::VectorXd(c.validation.stats.rms_position));
    cj["validation_rms_orientation"] =
        lrcal::ToJson(Eigen::VectorXd(c.validation.stats.rms_orientation));
    cj["validation_max_position"] = lrcal::ToJson(Eigen::VectorXd(c.validation.stats.max_position));
    cj["validation_max_orientation"] =
        lrcal::ToJson(Eigen::VectorXd(c.validation.stats.max_orientation));
    cases.push_back(cj);
  }
  j["cases"] = cases;
  j["nominal_validation_rms_position"] =
      lrcal::ToJson(Eigen::VectorXd(r.nominal_validation.stats.rms_position));
  return j;
}

std::string PaperCasesText(const RobotModel& robot, const PaperCasesResult& r,
                           const PaperCaseOptions& options) {
  std::ostringstream out;
  out << "lrcal paper: one realisation (seed " << options.seed << ") of the paper's cases\n"
      << "candidate pool: " << r.pool_report.ToString() << "\n"
      << "validation set: " << r.validation_report.ToString() << "\n";
  for (const auto& c : r.cases) {
    out << c.label << ": " << c.selection.indices.size() << " of " << r.pool.size()
        << " by E-optimality ("
        << SelectionMethodName(c.label == "case 1" ? options.case1_selection.method
                                                   : options.case2_selection.method)
        << ", " << c.selection.evaluations << " evaluations), sigma_min(G) = " << c.selection.score
        << "; " << c.summary.BriefReport() << "\n";
  }
  out << "\n" << PaperParameterTable(robot, r).ToText() << "\n" << PaperValidationTable(r).ToText();
  out << "\nOne realisation cannot reproduce the paper's digits; `lrcal run "
         "studies/paper.yaml` shows where they fall in the distribution.\n";
  return out.str();
}

}  // namespace lrcal
