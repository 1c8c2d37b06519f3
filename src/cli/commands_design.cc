// lrcal design: choose measurement configurations from a candidate pool by an observability
// criterion, and compare the choice with random designs of the same size.

#include "cli_common.h"
#include "lrcal/core/text_table.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/design/design_choice.h"
#include "lrcal/design/measurable_pool.h"
#include "lrcal/identification/identifiability.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/socket_data.h"
#include "lrcal/measurement/point_measurement.h"
#include "lrcal/measurement/ranger_measurement.h"
#include "lrcal/measurement/socket_measurement.h"
#include "lrcal/measurement/tree_measurement.h"

namespace lrcal::cli {

namespace {

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
      "method", po::value<std::string>()->default_value("exchange"),
      "exhaustive, greedy (forward), backward, exchange, sampled, random")(
      "scaling", po::value<std::string>()->default_value("si"),
      "columns of G: si (the paper), unit (unit-norm), expected (× expected error)")(
      "estimate-ranger", po::value<std::string>()->default_value("none"),
      "ranger terms to estimate: none, offset, scale, offset,scale (reading = (1+s) h + o)")(
      "estimate-plane", po::value<std::string>()->default_value("none"), "plane terms in the set")(
      "fix", po::value<std::string>(), "parameters left out, comma-separated")(
      "out", po::value<std::string>(),
      "write the chosen configurations (CSV; a socket column for --sensor socket)");
  // Every sensor but the ranger: its configurations chosen as blocks of its values per
  // configuration, the terms the pool cannot separate held at nominal.
  AddSensorOptions(o);
  o.add_options()("socket", po::value<std::vector<std::string>>()->composing(),
                  "--sensor socket with --generate: a socket's nominal position as x,y,z (m, "
                  "base frame), one per socket id 0, 1, ... in order");
  AddFrameTermOptions(o);
  AddSettingOptions(o, SelectionOptions::Settings(), {"samples", "restarts"});
  AddSettingOptions(o, DesignRequest::Settings());
}

struct ResolvedPool {
  TargetedConfigurations configs;
  SamplingReport report;
  std::string source;
};

// The candidate pool (generated, or read and filtered by the nominal beam), with what was
// rejected and why. A tracker (`beam` false) sees its target anywhere: no beam has to hit.
ResolvedPool ResolvePool(const po::variables_map& vm, const Setup& setup, std::uint64_t seed,
                         bool beam) {
  const RobotModel& robot = setup.rig.robot;
  if (vm.count("pool") == vm.count("generate"))
    throw InputError("--pool/--generate", "give exactly one: a pool CSV or a number to generate");
  ResolvedPool pool{TargetedConfigurations(robot.num_links()), {}, ""};
  if (vm.count("generate")) {
    const int n = vm["generate"].as<int>();
    if (n < 1 || n > 100000)
      throw InputError("--generate", "expected 1 to 100,000 candidates, got " + std::to_string(n));
    SamplingOptions sampling;
    sampling.ranger = setup.rig.ranger;
    sampling.require_beam_hit = beam;
    pool.configs = SampleConfigurations(
        robot, setup.planes, std::vector<int>(setup.planes.size(), n),
        RandomStream(seed, 0, 0, RandomPurpose::kPool), sampling, &pool.report);
    pool.source = "generated: " + pool.report.ToString();
    return pool;
  }
  const std::string path = vm["pool"].as<std::string>();
  if (!beam) {
    pool.configs = ReadRobotConfigurations(path, robot, nullptr);
    pool.source = path + ": " + std::to_string(pool.configs.size()) + " configurations";
    if (pool.configs.size() == 0) throw InputError("--pool", "no candidate configurations");
    return pool;
  }
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

// A sensor other than the ranger: its kind with every term (--fix aside) and its candidates;
// a socket design's socket ids, which its output names.
struct KindPool {
  std::unique_ptr<MeasurementKind> kind;
  ResolvedPool pool;
  std::vector<int> socket_ids;
};

// The configurations of `drawn` where `kind` measures at its nominal terms; the others are
// named on stderr (a pool file's line) and counted in the report.
TargetedConfigurations Measurable(const MeasurementKind& kind, const TargetedConfigurations& drawn,
                                  const std::string& path, SamplingReport* report) {
  std::vector<std::string> reasons;
  TargetedConfigurations kept = MeasurableConfigurations(kind, drawn, report, &reasons);
  for (std::size_t i = 0; i < reasons.size(); ++i)
    if (reasons[i] != "ok")
      std::cerr << "lrcal design: " << path << " configuration " << i + 1 << " (line " << i + 2
                << ") rejected: " << reasons[i] << "\n";
  return kept;
}

// --sensor socket: the sockets of a pool file (its socket column; their nominal positions the
// nominal arm's mean ball centre) or of --socket for --generate.
KindPool SocketKindPool(const po::variables_map& vm, const Setup& setup, std::uint64_t seed,
                        const SamplingOptions& sampling) {
  const RobotModel& robot = setup.rig.robot;
  KindPool kp;
  if (vm.count("pool")) {
    if (vm.count("socket"))
      throw InputError("--socket",
                       "the sockets of --pool are its socket column's; --socket "
                       "places them for --generate");
    const std::string path = vm["pool"].as<std::string>();
    const SocketData data = ReadSocketData(path, robot);
    kp.socket_ids = data.ids;
    kp.kind = MakeSocketKind(robot, data, vm);
    kp.pool.configs = SeatedConfigurations(robot, *kp.kind, data.values.configs, &kp.pool.report);
    kp.pool.source = path + ": " + kp.pool.report.ToString() + ", seated in their sockets";
    return kp;
  }
  if (!vm.count("socket"))
    throw InputError("--socket",
                     "--sensor socket with --generate needs the sockets' nominal "
                     "positions: give --socket x,y,z (m, base frame) per socket");
  // In this order, so that the first bad option is the one named.
  std::vector<Eigen::Vector3d> positions = ResolveSocketPositions(vm);
  const Eigen::Vector3d tool_point = ResolveToolPoint(vm, "socket", false);
  const SocketSetup socket =
      SocketSetup::Numbered(std::move(positions), tool_point, ResolveSocketDistances(vm));
  kp.socket_ids = socket.ids;
  const auto kind = std::make_unique<SocketMeasurement>(robot, socket, FixList(vm, robot), "--fix");
  kp.pool.configs = SampleSocketConfigurations(*kind, vm["generate"].as<int>(), seed, 0, sampling,
                                               &kp.pool.report);
  kp.pool.source = "generated: " + kp.pool.report.ToString() + ", seated in their sockets";
  kp.kind = kind->Without({});
  return kp;
}

// The kind and candidates of --sensor scanner, point, pose, contact or socket: a pool file, or
// --generate draws (anywhere for a tracker; aimed at the planes and kept where every beam meets
// its plane for a scanner; aimed and seated on the planes for contacts; seated in the sockets).
KindPool ResolveKindPool(const po::variables_map& vm, const Setup& setup, const std::string& sensor,
                         std::uint64_t seed) {
  const RobotModel& robot = setup.rig.robot;
  if (vm.count("pool") == vm.count("generate"))
    throw InputError("--pool/--generate", "give exactly one: a pool CSV or a number to generate");
  const int n = vm.count("generate") ? vm["generate"].as<int>() : 1;
  if (n < 1 || n > 100000)
    throw InputError("--generate", "expected 1 to 100,000 candidates, got " + std::to_string(n));
  SamplingOptions sampling;
  sampling.ranger = setup.rig.ranger;
  sampling.require_beam_hit = sensor == "contact";
  if (sensor == "socket") return SocketKindPool(vm, setup, seed, sampling);
  KindPool kp;
  if (sensor == "scanner")
    kp.kind = MakeScannerKind(robot, setup.planes, setup.rig.ranger, vm);
  else if (sensor == "contact")
    kp.kind = MakeContactKind(robot, setup.planes, vm["flush"].as<bool>(), vm);
  else
    kp.kind = MakeTrackerKind(robot, sensor, vm);
  const std::vector<int> counts(static_cast<std::size_t>(setup.planes.size()), n);
  TargetedConfigurations drawn;
  if (vm.count("pool")) {
    const std::string path = vm["pool"].as<std::string>();
    drawn = ReadRobotConfigurations(
        path, robot, sensor == "point" || sensor == "pose" ? nullptr : &setup.planes);
    kp.pool.configs = sensor == "contact"
                          ? SeatedConfigurations(robot, *kp.kind, drawn, &kp.pool.report)
                          : Measurable(*kp.kind, drawn, path, &kp.pool.report);
    kp.pool.source = path + ": " + kp.pool.report.ToString();
  } else if (sensor == "scanner") {
    kp.pool.configs = SampleScannerConfigurations(dynamic_cast<const ScannerMeasurement&>(*kp.kind),
                                                  counts, seed, 0, sampling, &kp.pool.report);
    kp.pool.source = "generated: " + kp.pool.report.ToString() + ", every beam on its plane";
  } else {
    drawn = SampleConfigurations(robot, setup.planes, counts,
                                 RandomStream(seed, 0, 0, RandomPurpose::kPool), sampling,
                                 &kp.pool.report);
    if (sensor == "contact")  // seated on their planes: the contacts' configurations
      kp.pool.configs = SeatedConfigurations(robot, *kp.kind, drawn, &kp.pool.report);
    else
      kp.pool.configs = std::move(drawn);
    kp.pool.source = "generated: " + kp.pool.report.ToString();
  }
  if (kp.pool.configs.size() == 0) throw InputError("--pool", "no usable candidate configurations");
  return kp;
}

// The chosen configurations: q1..qN (and plane with several), or with a socket column.
void WriteChosen(const std::string& path, const KindPool& kp,
                 const TargetedConfigurations& chosen) {
  if (kp.socket_ids.empty()) {
    WriteConfigurations(path, chosen);
    return;
  }
  MeasuredValues values{chosen,
                        std::vector<double>(static_cast<std::size_t>(3 * chosen.size()), 0.0),
                        std::vector<int>(static_cast<std::size_t>(chosen.size()), 1)};
  WriteSocketData(path, kp.socket_ids, values);
}

// The request of the options: criterion I weighs by --poses, else by --workspace poses.
// `model` null: a tree's design, which refuses I before.
DesignRequest ResolveRequest(const po::variables_map& vm, const MeasurementModel* model,
                             std::uint64_t seed) {
  DesignRequest request;
  request.count = vm["select"].as<int>();
  request.seed = seed;
  ReadSettingOptions(vm, DesignRequest::Settings(), &request);  // --workspace first: the task
  const std::string criterion = vm["criterion"].as<std::string>();
  if (criterion != "I") {
    try {
      request.selection.criterion = ParseDesignCriterion(criterion, "--criterion");
    } catch (const InputError&) {
      throw InputError("--criterion", "unknown criterion '" + criterion +
                                          "'; expected E, D, A, O1, O2, O3, O4, O5 or I (task)");
    }
  } else if (vm.count("poses")) {
    const std::string file = vm["poses"].as<std::string>();
    request.task = TaskPosesAt(
        *model, ReadRobotConfigurations(file, model->robot(), &model->nominal_planes()), file);
  } else {
    request.task =
        TaskPosesAt(*model, WorkspacePoses(model->robot(), request.workspace, seed), "workspace");
  }
  request.selection.method = ParseSelectionMethod(vm["method"].as<std::string>(), "--method");
  ReadSettingOptions(vm, SelectionOptions::Settings(), &request.selection);
  request.scaling = ParseDesignScaling(vm["scaling"].as<std::string>(), "--scaling");
  return request;
}

}  // namespace

// --sensor: one kind (a mixed design is not chosen yet); a kind other than the ranger takes
// none of the ranger's terms (a scanner and a contact take --estimate-plane).
std::string DesignSensor(const po::variables_map& vm) {
  const std::vector<std::string> sensors = ResolveSensors(vm);
  if (sensors.size() != 1 || sensors[0] == "mixed")
    throw InputError("--sensor", "'" + CellExcerpt(vm["sensor"].as<std::string>()) +
                                     "': lrcal design chooses for one sensor at a time (ranger, "
                                     "scanner, point, pose, socket or contact)");
  const std::string sensor = sensors[0];
  if (sensor == "scanner" || sensor == "contact")
    RefuseRangerOptions(vm, sensor, {"estimate-ranger", "estimate-base", "estimate-tool"});
  else if (sensor != "ranger")
    RefuseRangerOptions(vm, sensor,
                        {"estimate-ranger", "estimate-plane", "estimate-base", "estimate-tool"});
  else if ((vm.count("instrument") && !vm["instrument"].defaulted()) || vm.count("target"))
    throw InputError(vm.count("target") ? "--target" : "--instrument",
                     "is a tracker's, a probe's or a ball's; give --sensor point, pose, contact "
                     "or socket");
  if (sensor != "socket" && vm.count("socket"))
    throw InputError("--socket",
                     "is the socket sensor's; --sensor " + sensor + " does not take it");
  return sensor;
}

namespace {

// A tree's chains measured together (tree_measurement.h), each by the ranger or a tracker.
std::unique_ptr<MeasurementKind> TreeKind(const po::variables_map& vm, const UrdfChains& tree,
                                          const std::string& sensor, const PlaneSet& planes) {
  std::vector<std::shared_ptr<const ChainMeasurement>> chains;
  for (std::size_t c = 0; c < tree.chains.size(); ++c) {
    const RobotFile& chain = tree.chains[c];
    std::shared_ptr<const MeasurementKind> kind;
    if (sensor == "ranger")
      kind = std::make_shared<RangerMeasurement>(
          MeasurementModel(chain.robot, planes,
                           ResolveParameterSet(chain.robot, vm, planes.size(), true)),
          chain.ranger);
    else
      kind = MakeTrackerKind(chain.robot, sensor, vm, true);
    chains.push_back(std::make_shared<ChainMeasurement>(kind, tree.placements[c]));
  }
  auto full = std::make_unique<TreeMeasurement>(chains);
  const std::vector<std::string> fixed =
      vm.count("fix") ? SplitList(vm["fix"].as<std::string>()) : std::vector<std::string>{};
  for (const std::string& name : fixed)
    if (std::find(full->parameter_names().begin(), full->parameter_names().end(), name) ==
        full->parameter_names().end())
      throw InputError("--fix", "'" + CellExcerpt(name) +
                                    "' is not a term of the tree's chains (a chain's own term is "
                                    "written with its tool link: left_tool.theta4)");
  if (fixed.empty()) return full;
  return full->Without(fixed);
}

// The tree's candidates: a whole-robot CSV (every joint by name) or uniform draws over the
// joints' ranges, those where some chain misses its plane left out.
ResolvedPool TreePool(const po::variables_map& vm, const UrdfChains& tree,
                      const MeasurementKind& kind, const PlaneSet& planes, std::uint64_t seed) {
  if (vm.count("pool") == vm.count("generate"))
    throw InputError("--pool/--generate", "give exactly one: a pool CSV or a number to generate");
  ResolvedPool pool{TargetedConfigurations(static_cast<int>(tree.joint_names.size())), {}, ""};
  TargetedConfigurations drawn;
  if (vm.count("generate")) {
    const int n = vm["generate"].as<int>();
    if (n < 1 || n > 100000)
      throw InputError("--generate", "expected 1 to 100,000 candidates, got " + std::to_string(n));
    drawn = UniformTreeConfigurations(tree, n, RandomStream(seed, 0, 0, RandomPurpose::kPool));
    if (planes.size() > 1) {  // the planes in turn
      TargetedConfigurations turned(drawn.num_joints());
      for (int i = 0; i < drawn.size(); ++i) turned.AddFrom(drawn, i, i % planes.size());
      drawn = std::move(turned);
    }
    pool.source = "generated: " + std::to_string(n) +
                  " whole-robot configurations, every joint "
                  "uniform in its range";
  } else {
    const std::string path = vm["pool"].as<std::string>();
    drawn = ReadTreeConfigurations(path, tree, planes.size() ? &planes : nullptr);
    pool.source = path;
  }
  const std::vector<std::string> reasons = kind.MissReasons(drawn, nullptr);
  std::vector<int> kept;
  for (int i = 0; i < drawn.size(); ++i)
    if (reasons[static_cast<std::size_t>(i)] == "ok") kept.push_back(i);
  pool.configs = drawn.Subset(kept);
  pool.source += "; " + std::to_string(kept.size()) + " where every chain measures";
  if (pool.configs.size() == 0) throw InputError("--pool", "no usable candidate configurations");
  return pool;
}

// design --tool-link a,b: configurations of the whole robot, every chain measured at each.
int TreeDesign(const po::variables_map& vm) {
  const UrdfChains tree = LoadTreeChains(vm);
  const std::uint64_t seed = ParseSeed(vm);
  const std::string sensor = DesignSensor(vm);
  if (vm["criterion"].as<std::string>() == "I")
    throw InputError("--criterion",
                     "I weighs one chain's tool poses; a tree's design takes E, D, "
                     "A or O1..O5");
  const PlaneSet planes = sensor == "ranger" ? ResolvePlanes(tree.chains[0], vm) : PlaneSet{};
  const std::unique_ptr<MeasurementKind> full = TreeKind(vm, tree, sensor, planes);
  const ResolvedPool pool = TreePool(vm, tree, *full, planes, seed);
  const std::vector<std::string> held = AnalyzeIdentifiability(*full, pool.configs).suggested_fixed;
  const DesignRequest request = ResolveRequest(vm, nullptr, seed);
  const DesignChoice choice = ChooseDesign(*full->Without(held), pool.configs, request);
  if (vm.count("out"))
    WriteConfigurations(vm["out"].as<std::string>(), pool.configs.Subset(choice.chosen.indices),
                        tree.joint_names);
  if (ResolveFormat(vm) == Format::kJson) {
    Json j;
    j["pool"] = {{"size", pool.configs.size()}, {"source", pool.source}};
    j.update(DesignChoiceJson(request, choice));
    j["sensor"] = sensor;
    j["tree"] = {{"tool_links", tree.tool_links()},
                 {"joints", tree.joint_names},
                 {"values_per_configuration", full->rows_per_configuration()}};
    j["held_at_nominal"] = held;
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "candidate pool: " << pool.source << "\n"
            << "tree: " << tree.chains.size() << " chains over " << tree.joint_names.size()
            << " joints, each measured at every configuration (" << full->rows_per_configuration()
            << " values); held at nominal, the pool cannot separate them:";
  for (const std::string& name : held) std::cout << " " << name;
  std::cout << (held.empty() ? " none\n" : "\n")
            << DesignChoiceText(request, choice, planes, pool.configs.size());
  if (vm.count("out")) std::cout << "wrote " << vm["out"].as<std::string>() << "\n";
  return 0;
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
  if (IsTreeRun(vm)) return TreeDesign(vm);
  const std::string sensor = DesignSensor(vm);
  const bool tracker = sensor != "ranger";
  const bool planar = sensor == "ranger" || sensor == "scanner" || sensor == "contact";
  Setup setup{LoadRobot(vm), PlaneSet{}};
  // A tracker or a socket reads no plane: without one, the horizontal plane through the base
  // only tags the candidates (as a study's tracker cell does), so a URDF without planes needs no
  // --plane.
  setup.planes = !planar && !vm.count("plane") && !setup.rig.planes ? PlaneSet(Plane{})
                                                                    : ResolvePlanes(setup.rig, vm);
  const std::uint64_t seed = ParseSeed(vm);
  KindPool kind_pool;
  if (tracker) kind_pool = ResolveKindPool(vm, setup, sensor, seed);
  const ResolvedPool& pool =
      tracker ? kind_pool.pool : (kind_pool.pool = ResolvePool(vm, setup, seed, true));
  MeasurementModel model(setup.rig.robot, setup.planes,
                         tracker ? MakeParameterSet(setup.rig.robot, PlaneTerms{})
                                 : ResolveParameterSet(setup.rig.robot, vm, setup.planes.size()));
  const DesignRequest request = ResolveRequest(vm, &model, seed);
  std::vector<std::string> held;
  DesignChoice choice;
  if (tracker) {
    held = AnalyzeIdentifiability(*kind_pool.kind, pool.configs).suggested_fixed;
    choice = ChooseDesign(*kind_pool.kind->Without(held), pool.configs, request);
  } else {
    choice = ChooseDesign(model, pool.configs, request);
  }
  if (vm.count("out"))
    WriteChosen(vm["out"].as<std::string>(), kind_pool, pool.configs.Subset(choice.chosen.indices));
  if (ResolveFormat(vm) == Format::kJson) {
    Json j;
    j["pool"] = {{"size", pool.configs.size()},
                 {"source", pool.source},
                 {"rejected", pool.report.rejected},
                 {"tried", pool.report.attempts}};
    j.update(DesignChoiceJson(request, choice));
    j["sensor"] = sensor;
    j["held_at_nominal"] = held;
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "candidate pool: " << pool.source << "\n";
  if (tracker) {
    const int rows = kind_pool.kind->rows_per_configuration();
    std::cout << "sensor: " << sensor << " (" << rows << (rows == 1 ? " value" : " values")
              << " per configuration); held at nominal, the pool cannot separate them:";
    for (const std::string& name : held) std::cout << " " << name;
    std::cout << (held.empty() ? " none\n" : "\n");
  }
  std::cout << DesignChoiceText(request, choice, setup.planes, pool.configs.size());
  if (vm.count("out")) std::cout << "wrote " << vm["out"].as<std::string>() << "\n";
  return 0;
}

}  // namespace lrcal::cli
