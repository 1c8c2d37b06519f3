// lrcal design: choose measurement configurations from a candidate pool by an observability
// criterion, and compare the choice with random designs of the same size.
#include <Eigen/Cholesky>
#include <chrono>
#include <cmath>
#include <sstream>

#include "cli_common.h"
#include "lrcal/core/text_table.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/design/design_certificate.h"
#include "lrcal/design/experiment_design.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/identification/pose_accuracy.h"
#include "lrcal/io/csv.h"
#include "lrcal/measurement/simulation.h"
#include "lrcal/study/statistics.h"

namespace lrcal::cli {

namespace {

// The criteria compared against random designs (O3 is E).
constexpr DesignCriterion kAllCriteria[] = {
    DesignCriterion::kE,  DesignCriterion::kD,  DesignCriterion::kA, DesignCriterion::kO1,
    DesignCriterion::kO2, DesignCriterion::kO4, DesignCriterion::kO5};

void AddDesignOptions(po::options_description& o) {
  AddCommonOptions(o);
  o.add_options()("pool", po::value<std::string>(), "candidate configurations CSV (q1..qN)")(
      "generate", po::value<int>(),
      "or: generate this many candidates (per plane; beam hits, non-singular)")(
      "seed", po::value<long long>()->default_value(1),
      "seed for --generate, exchange kicks, baseline")("select", po::value<int>()->required(),
                                                       "configurations to choose (k)")(
      "criterion", po::value<std::string>()->default_value("E"),
      "E (=O3), D, A, O1, O2, O4, O5, or I (task: the predicted RMS position error at --poses, "
      "or at --workspace poses)")(
      "poses", po::value<std::string>(),
      "criterion I: the poses where accuracy matters (a configurations CSV)")(
      "workspace", po::value<int>()->default_value(200),
      "criterion I without --poses: this many poses drawn over the joint ranges (--seed)")(
      "method", po::value<std::string>()->default_value("exchange"),
      "exhaustive, greedy (forward), backward, exchange, sampled, random")(
      "scaling", po::value<std::string>()->default_value("si"),
      "columns of G: si (the paper), unit (unit-norm), expected (× expected error)")(
      "expected-angle-mrad", po::value<double>()->default_value(1.0),
      "expected angle error (mrad)")("expected-length-mm", po::value<double>()->default_value(1.0),
                                     "expected length error (mm)")(
      "restarts", po::value<int>()->default_value(4),
      "exchange: starts (backward design + random)")(
      "samples", po::value<int>()->default_value(1000), "sampled: random subsets tried")(
      "baseline", po::value<int>()->default_value(1000), "random designs for the baseline")(
      "estimate-ranger", po::value<std::string>()->default_value("none"),
      "ranger terms to estimate: none, offset, scale, offset,scale (reading = (1+s) h + o)")(
      "estimate-plane", po::value<std::string>()->default_value("none"), "plane terms in the set")(
      "fix", po::value<std::string>(), "parameters left out, comma-separated")(
      "out", po::value<std::string>(), "write the chosen configurations (CSV)");
}

struct ResolvedPool {
  ConfigurationSet configs;
  SamplingReport report;
  std::string source;
};

// The candidate pool (generated, or read and filtered by the nominal beam), with what was
// rejected and why.
ResolvedPool ResolvePool(const po::variables_map& vm, const Setup& setup, std::uint64_t seed) {
  const RobotModel& robot = setup.rig.robot;
  if (vm.count("pool") == vm.count("generate"))
    throw InputError("--pool/--generate", "give exactly one: a pool CSV or a number to generate");
  ResolvedPool pool{ConfigurationSet(robot.num_links()), {}, ""};
  if (vm.count("generate")) {
    const int n = vm["generate"].as<int>();
    if (n < 1 || n > 100000)
      throw InputError("--generate", "expected 1 to 100,000 candidates, got " + std::to_string(n));
    SamplingOptions sampling;
    sampling.ranger = setup.rig.ranger;
    pool.configs = SampleConfigurations(
        robot, setup.planes, std::vector<int>(setup.planes.size(), n),
        RandomStream(seed, 0, 0, RandomPurpose::kPool), sampling, &pool.report);
    pool.source = "generated: " + pool.report.ToString();
    return pool;
  }
  const std::string path = vm["pool"].as<std::string>();
  CandidatePool usable = UsableCandidates(robot, setup.planes, setup.rig.ranger,
                                          ReadRobotConfigurations(path, robot, &setup.planes));
  for (std::size_t i = 0; i < usable.misses.size(); ++i)
    if (usable.misses[i] != BeamMiss::kNone)
      std::cerr << "lrcal design: " << path << " configuration " << i + 1 << " (line " << i + 2
                << ") rejected: " << BeamMissName(usable.misses[i]) << "\n";
  pool.configs = std::move(usable.configs);
  pool.report = usable.report;
  pool.source = path + ": " + pool.report.ToString();
  if (pool.configs.size() == 0) throw InputError("--pool", "no usable candidate configurations");
  return pool;
}

bool IsTaskCriterion(const po::variables_map& vm) {
  return vm["criterion"].as<std::string>() == "I";
}

// The task criterion's poses (--poses, else --workspace poses over the joint ranges) and the
// position rows of ∂(pose)/∂e at them (3M × n, nominal model), computed once per command;
// empty (count 0) unless --criterion I.
struct TaskPoseSet {
  int count = 0;
  std::string source;
  Eigen::MatrixXd position_rows;
};

TaskPoseSet ResolveTaskPoses(const po::variables_map& vm, const MeasurementModel& model) {
  TaskPoseSet task;
  if (!IsTaskCriterion(vm)) return task;
  const ConfigurationSet poses =
      vm.count("poses")
          ? ReadRobotConfigurations(vm["poses"].as<std::string>(), model.robot(),
                                    &model.nominal_planes())
          : WorkspacePoses(model.robot(), vm["workspace"].as<int>(), vm["seed"].as<long long>());
  task.count = poses.size();
  task.source = vm.count("poses") ? vm["poses"].as<std::string>() : "workspace";
  const std::vector<double> zero(model.num_parameters(), 0.0);
  const Eigen::MatrixXd J6 = PoseJacobian(model, zero.data(), poses);
  task.position_rows.resize(3 * task.count, model.num_parameters());
  for (int j = 0; j < task.count; ++j)
    task.position_rows.middleRows(3 * j, 3) = J6.middleRows(6 * j, 3);
  return task;
}

SelectionOptions ResolveSelection(const po::variables_map& vm) {
  SelectionOptions options;
  // I is A on the task-weighted G (TaskWeightedJacobian).
  const std::string criterion = vm["criterion"].as<std::string>();
  try {
    options.criterion =
        criterion == "I" ? DesignCriterion::kA : ParseDesignCriterion(criterion, "--criterion");
  } catch (const InputError&) {
    throw InputError("--criterion", "unknown criterion '" + criterion +
                                        "'; expected E, D, A, O1, O2, O3, O4, O5 or I (task)");
  }
  options.method = ParseSelectionMethod(vm["method"].as<std::string>(), "--method");
  options.restarts = vm["restarts"].as<int>();
  options.samples = vm["samples"].as<int>();
  if (options.restarts < 1) throw InputError("--restarts", "expected at least 1");
  if (options.samples < 1) throw InputError("--samples", "expected at least 1");
  return options;
}

// A finite, positive option value (an expected error in mm or mrad).
double PositiveMm(const po::variables_map& vm, const std::string& name) {
  const double v = vm[name].as<double>();
  if (!(std::isfinite(v) && v > 0))
    throw InputError("--" + name, "expected a finite value > 0, got " + std::to_string(v));
  return v;
}

// G of the pool at the nominal model, columns scaled as asked (criterion I: task-weighted, the
// study's selection.criterion I).
Eigen::MatrixXd ScaledJacobian(const po::variables_map& vm, const MeasurementModel& model,
                               const ConfigurationSet& pool, DesignScaling scaling,
                               const TaskPoseSet& task) {
  if (task.count > 0)
    return TaskWeightedJacobian(DesignJacobian(model, pool, DesignScaling::kSI, 0, 0),
                                task.position_rows);
  return DesignJacobian(model, pool, scaling, PositiveMm(vm, "expected-angle-mrad") * 1e-3,
                        PositiveMm(vm, "expected-length-mm") * 1e-3);
}

Eigen::MatrixXd NormalMatrixOfRows(const Eigen::MatrixXd& G, const std::vector<int>& rows) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(G.cols(), G.cols());
  for (int r : rows) A += G.row(r).transpose() * G.row(r);
  return A;
}

// Every index of the chosen set against `baseline` random designs of the same size.
void CompareWithRandomDesigns(const Eigen::MatrixXd& G, const SelectionResult& chosen, int k,
                              int baseline, std::uint64_t seed, Table* table, Json* indices) {
  const Eigen::MatrixXd A_chosen = NormalMatrixOfRows(G, chosen.indices);
  std::vector<std::vector<double>> random_scores(std::size(kAllCriteria));
  SelectionOptions random_options;
  random_options.method = SelectionMethod::kRandom;
  for (int b = 0; b < baseline; ++b) {
    const SelectionResult r = SelectConfigurations(
        G, k, random_options,
        RandomStream(seed, 2, static_cast<std::uint64_t>(b), RandomPurpose::kSelection));
    const Eigen::MatrixXd A = NormalMatrixOfRows(G, r.indices);
    for (std::size_t c = 0; c < std::size(kAllCriteria); ++c)
      random_scores[c].push_back(CriterionScore(A, k, kAllCriteria[c]));
  }
  *indices = Json::object();
  for (std::size_t c = 0; c < std::size(kAllCriteria); ++c) {
    const char* name = DesignCriterionName(kAllCriteria[c]);
    const double value = CriterionScore(A_chosen, k, kAllCriteria[c]);
    const Distribution d = Describe(random_scores[c]);
    const double rank = PercentileRank(random_scores[c], value);
    table->AddRow(
        {name, Fixed(value, 6), Fixed(d.mean, 6), Fixed(d.p5, 6), Fixed(d.p95, 6), Fixed(rank, 1)});
    (*indices)[name] = {{"chosen", value},
                        {"random_mean", d.mean},
                        {"random_p5", d.p5},
                        {"random_p95", d.p95},
                        {"percentile", rank}};
  }
}

// What the task criterion predicts for the chosen rows: tr(W C)/M with C = (G_SᵀG_S)⁻¹ (SI) and
// W the poses' position rows, no ridge, computed directly (the score, −tr of the inverse of the
// task-weighted matrix, loses ~1e-6 to its conditioning): √ of it is the RMS position error (m)
// per 1 m of reading noise σ (per mm, mm).
Json TaskJson(const TaskPoseSet& task, const MeasurementModel& model, const ConfigurationSet& pool,
              const std::vector<int>& chosen) {
  const Eigen::MatrixXd G = DesignJacobian(model, pool.Subset(chosen), DesignScaling::kSI, 0, 0);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(G.transpose() * G);
  const Eigen::MatrixXd& P = task.position_rows;
  const double sum = (P * ldlt.solve(P.transpose())).trace();
  return {{"poses", task.count},
          {"source", task.source},
          {"rms_position_per_unit_sigma", std::sqrt(sum / task.count)}};
}

std::string CriterionText(const TaskPoseSet& task, const MeasurementModel& model,
                          const ConfigurationSet& pool, const SelectionOptions& options,
                          const SelectionResult& chosen) {
  std::ostringstream out;
  if (task.count == 0) {
    out << DesignCriterionName(options.criterion) << " = " << chosen.score;
    return out.str();
  }
  const Json t = TaskJson(task, model, pool, chosen.indices);
  out << "I (predicted RMS position error at " << t["poses"].get<int>() << " "
      << t["source"].get<std::string>()
      << " poses: " << t["rms_position_per_unit_sigma"].get<double>()
      << " mm per mm of reading noise)";
  return out.str();
}

Json CertificateJson(const DesignCertificate& certificate, const std::string& statement) {
  Json j = {{"available", certificate.available},
            {"statement", statement},
            {"iterations", certificate.iterations}};
  if (certificate.available) {
    j["bound"] = certificate.bound;
    j["achieved"] = certificate.achieved;
    j["efficiency"] = certificate.efficiency;
  }
  return j;
}

// "chosen per plane: plane 1: 19, wall: 6\n" with several planes, else "".
std::string PerPlaneText(const PlaneSet& planes, const std::vector<int>& per_plane) {
  if (planes.size() < 2) return "";
  std::string out = "chosen per plane:";
  for (int p = 0; p < planes.size(); ++p)
    out += (p ? ", " : " ") + planes.Label(p) + ": " + std::to_string(per_plane[p]);
  return out + "\n";
}

}  // namespace

int DesignCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal design options");
  AddDesignOptions(o);
  po::variables_map vm;
  if (!Parse("design", "--pool C.csv|--generate N --select K [options] --out chosen.csv", o, args,
             &vm))
    return 0;
  if (vm.count("out")) CheckOutputFile(vm["out"].as<std::string>(), "--out");
  const Setup setup = ResolveSetup(vm);
  const long long seed_value = vm["seed"].as<long long>();
  if (seed_value < 0) throw InputError("--seed", "expected a non-negative integer");
  const std::uint64_t seed = static_cast<std::uint64_t>(seed_value);
  const ResolvedPool pool = ResolvePool(vm, setup, seed);
  MeasurementModel model(setup.rig.robot, setup.planes,
                         ResolveParameterSet(setup.rig.robot, vm, setup.planes.size()));
  const SelectionOptions options = ResolveSelection(vm);
  const DesignScaling scaling = ParseDesignScaling(vm["scaling"].as<std::string>(), "--scaling");
  const TaskPoseSet task = ResolveTaskPoses(vm, model);  // empty unless --criterion I
  const Eigen::MatrixXd G = ScaledJacobian(vm, model, pool.configs, scaling, task);
  const int k = vm["select"].as<int>();

  const auto t0 = std::chrono::steady_clock::now();
  const SelectionResult chosen =
      SelectConfigurations(G, k, options, RandomStream(seed, 1, 0, RandomPurpose::kSelection));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const int baseline = vm["baseline"].as<int>();
  if (baseline < 1 || baseline > 1000000)
    throw InputError("--baseline",
                     "expected 1 to 1,000,000 random designs, got " + std::to_string(baseline));
  Table t({"index", "chosen", "random mean", "random p5", "random p95", "percentile of chosen"},
          "Observability of the chosen " + std::to_string(k) + " of " +
              std::to_string(pool.configs.size()) + " against " + std::to_string(baseline) +
              " random designs (G scaled: " + DesignScalingName(scaling) +
              "; E = sigma_min, D = log det, A = -trace inv)");
  Json indices;
  CompareWithRandomDesigns(G, chosen, k, baseline, seed, &t, &indices);
  const DesignCertificate certificate = CertifyDesign(G, chosen.indices, options.criterion);
  const std::string statement =
      certificate.ToString(options.criterion, k, static_cast<int>(pool.configs.size()));
  if (vm.count("out"))
    WriteConfigurations(vm["out"].as<std::string>(), pool.configs.Subset(chosen.indices));
  const PlaneSet& planes = setup.planes;
  std::vector<int> per_plane(planes.size(), 0);  // the chosen (configuration, plane) rows
  for (int i : chosen.indices) ++per_plane[pool.configs.plane(i)];

  if (ResolveFormat(vm) == Format::kJson) {
    Json j;
    j["pool"] = {{"size", pool.configs.size()},
                 {"source", pool.source},
                 {"rejected", pool.report.rejected},
                 {"tried", pool.report.attempts}};
    j["method"] = SelectionMethodName(options.method);
    j["criterion"] =
        vm["criterion"].as<std::string>() == "I" ? "I" : DesignCriterionName(options.criterion);
    if (task.count > 0) j["task"] = TaskJson(task, model, pool.configs, chosen.indices);
    j["scaling"] = DesignScalingName(scaling);
    j["selected"] = chosen.indices;
    j["selected_per_plane"] = per_plane;
    j["score"] = chosen.score;
    j["evaluations"] = chosen.evaluations;
    j["seconds"] = seconds;
    j["indices"] = indices;
    j["certificate"] = CertificateJson(certificate, statement);
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "candidate pool: " << pool.source << "\n"
            << "chose " << k << " of " << pool.configs.size() << " by "
            << SelectionMethodName(options.method) << ", criterion "
            << CriterionText(task, model, pool.configs, options, chosen) << " ("
            << chosen.evaluations << " evaluations, " << Fixed(seconds * 1e3, 1) << " ms)\n"
            << "chosen (0-based pool indices):";
  for (int i : chosen.indices) std::cout << " " << i;
  std::cout << "\n"
            << PerPlaneText(planes, per_plane) << "certificate: " << statement << "\n\n"
            << t.ToText();
  if (vm.count("out")) std::cout << "wrote " << vm["out"].as<std::string>() << "\n";
  return 0;
}

}  // namespace lrcal::cli
