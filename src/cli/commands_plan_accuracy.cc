// lrcal plan-accuracy: the cheapest campaign (configurations × readings per configuration) that
// meets an accuracy target with a stated confidence, found with the first-order prediction and
// confirmed by Monte Carlo.
//
// The set-up is a study file's base settings (robot, plane, truth, noise σ per reading, pool,
// selection method and criterion, validation set); its sweep is ignored. The target is on the
// distribution over calibrations of the largest per-axis validation metric (e.g. rms_pos: the
// largest of the RMS position errors along x, y, z over the validation poses): its quantile at the
// confidence must not exceed the target.
//
// Search: for each number of configurations k the study's selection chooses the design; the
// first-order prediction (LinearisedValidationDraws, 4000 draws at one reading per configuration)
// gives the quantile q₁(k). The mean of R readings has σ/√R, and the linearised errors scale with
// it, so q(k, R) = q₁(k)/√R and the fewest readings are R(k) = ⌈(q₁(k)/target)²⌉. Cost:
// k·(configuration cost) + k·R·(reading cost) (+ planes·(plane cost)). Confirmation: the cheapest
// campaign, the next cheaper one (one reading fewer per configuration) and the runner-ups are run
// as an ordinary study (a file in --out, rerunnable with another seed).
//
// Candidate planes: when the study's plane is a list of two or more, every subset of them (with
// a number of planes in --planes) is searched like the whole set-up, each with its own pool drawn
// for its planes; the confirmation study then sweeps the plane lists and pools too.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

#include "cli_common.h"
#include "lrcal/core/data_dir.h"
#include "lrcal/core/json.h"
#include "lrcal/core/text_table.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/kinematics/validation_metric.h"
#include "lrcal/report/run_tables.h"
#include "lrcal/study/runner.h"
#include "lrcal/study/statistics.h"
#include "lrcal/study/study.h"
#include "lrcal/study/trial_store.h"
#include "study/trial_pipeline.h"

namespace lrcal::cli {

namespace {

namespace fs = std::filesystem;

// --target METRIC=VALUE[mm|mrad]
struct Target {
  std::string metric;  // rms_pos, rms_ori, max_pos, max_ori
  int first = 0;       // index of its x component in TrialRecord::validation
  double value = 0;    // SI
  std::string unit;    // mm or mrad
  double shown = 0;    // in `unit`
};

Target ParseTarget(const std::string& text) {
  const auto eq = text.find('=');
  const std::string expected =
      "expected METRIC=VALUE with a unit, e.g. rms_pos=0.05mm or rms_ori=0.1mrad (metrics " +
      NameList(kValidationMetricNames) + "), got '" + text + "'";
  if (eq == std::string::npos) throw InputError("--target", expected);
  Target t;
  t.metric = text.substr(0, eq);
  ValidationMetric metric{};
  if (!TryParseName(kValidationMetricNames, t.metric, &metric))
    throw InputError("--target", expected);
  t.first = 3 * static_cast<int>(metric);
  std::string value = text.substr(eq + 1);
  t.unit = TableUnit(metric);
  if (value.size() > t.unit.size() &&
      value.compare(value.size() - t.unit.size(), t.unit.size(), t.unit) == 0)
    value.resize(value.size() - t.unit.size());
  else
    throw InputError("--target", "the value needs its unit (" + t.unit + "): " + expected);
  char* end = nullptr;
  t.shown = std::strtod(value.c_str(), &end);
  if (value.empty() || *end != '\0' || !(t.shown > 0) || !std::isfinite(t.shown))
    throw InputError("--target", expected);
  t.value = t.shown * 1e-3;
  return t;
}

// "a:b" or "a:b:step" (whole numbers).
std::vector<int> ParseRange(const std::string& text, const std::string& option, int lo_limit) {
  int a = 0, b = 0, step = 1;
  char c1 = 0, c2 = 0;
  std::istringstream in(text);
  in >> a >> c1 >> b;
  if (in && !in.eof() && in.peek() == ':') in >> c2 >> step;
  if (!in || c1 != ':' || a < lo_limit || b < a || step < 1 || !in.eof())
    throw InputError(option, "expected FIRST:LAST or FIRST:LAST:STEP with " +
                                 std::to_string(lo_limit) + " <= FIRST <= LAST, got '" + text +
                                 "'");
  std::vector<int> out;
  for (int v = a; v <= b; v += step) out.push_back(v);
  if (out.back() != b) out.push_back(b);
  return out;
}

// --cost configuration=30s,reading=1s[,plane=600s] (seconds per configuration move, per reading
// and per plane set up).
void ParseCost(const std::string& text, double* per_configuration, double* per_reading,
               double* per_plane) {
  const std::string expected =
      "expected configuration=SECONDSs,reading=SECONDSs[,plane=SECONDSs], e.g. "
      "configuration=30s,reading=1s,plane=600s, got '" +
      text + "'";
  std::istringstream in(text);
  std::string part;
  bool got_c = false, got_r = false;
  while (std::getline(in, part, ',')) {
    const auto eq = part.find('=');
    if (eq == std::string::npos || part.back() != 's') throw InputError("--cost", expected);
    const std::string key = part.substr(0, eq), value = part.substr(eq + 1, part.size() - eq - 2);
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !(v >= 0)) throw InputError("--cost", expected);
    if (key == "configuration") {
      *per_configuration = v;
      got_c = true;
    } else if (key == "reading") {
      *per_reading = v;
      got_r = true;
    } else if (key == "plane") {
      *per_plane = v;
    } else {
      throw InputError("--cost", expected);
    }
  }
  if (!got_c || !got_r) throw InputError("--cost", expected);
}

// The quantile at `confidence` of the largest per-axis component of the target metric.
double WorstAxisQuantile(const Eigen::MatrixXd& draws, const Target& t, double confidence) {
  std::vector<double> worst(static_cast<std::size_t>(draws.rows()));
  for (Eigen::Index d = 0; d < draws.rows(); ++d)
    worst[d] = std::max({draws(d, t.first), draws(d, t.first + 1), draws(d, t.first + 2)});
  return Quantile(&worst, 100 * confidence);
}

// Which of the set-up's candidate planes a campaign measures on (all of them when the set-up
// has no candidates to choose from), with its own pool of candidate configurations.
struct PlaneSubset {
  Json planes;                     // the study's plane list for it; null: the set-up's as given
  std::string label;               // e.g. "table+wall", empty without candidates
  std::vector<std::string> names;  // the planes' names (or 1-based indices)
  std::string pool_file;
  std::vector<int> counts;  // configurations to consider
  int num_planes = 1;       // planes to set up (for the cost)
};

struct Campaign {
  int subset = 0;  // index into the planner's plane subsets
  int configurations = 0, repetitions = 0;
  double predicted = 0;  // SI: the quantile predicted
  double cost = 0;       // seconds
  double mc = NAN, mc_low = NAN, mc_high = NAN;
  long long trials = 0;
  std::string label;
};

// A study file for the set-up with the given cells (zip of configurations and repetitions). The
// candidates and the validation set are the files written beside it, so that another seed
// changes only the noise.
std::string WriteStudy(const Study& base, const std::string& path, const std::string& name,
                       int trials, std::uint64_t seed, const std::vector<Campaign>& campaigns,
                       const std::vector<PlaneSubset>& subsets, const std::string& validation_file,
                       double stop_precision = 0) {
  Json settings = Json::parse(base.base.dump());
  settings.erase("robot_file_fnv1a");
  settings["robot"] = fs::absolute(ResolveRobotPath(base.base["robot"], base.folder())).string();
  // The configuration files are beside the study file, named relative to it: the plan's
  // folder can be moved or copied to another machine.
  const PlaneSubset& first = subsets.at(campaigns.at(0).subset);
  settings["pool"] = {{"file", fs::path(first.pool_file).filename().string()},
                      {"min_singular_value", base.base["pool"]["min_singular_value"]}};
  if (!first.planes.is_null()) settings["plane"] = first.planes;
  settings["validation"] = {{"file", fs::path(validation_file).filename().string()}};
  Json counts = Json::array(), reps = Json::array(), planes = Json::array(), pools = Json::array(),
       plane_labels = Json::array();
  bool several_subsets = false;
  for (const Campaign& c : campaigns) {
    counts.push_back(c.configurations);
    reps.push_back(c.repetitions);
    const PlaneSubset& sub = subsets.at(c.subset);
    several_subsets |= c.subset != campaigns[0].subset;
    planes.push_back(sub.planes);
    pools.push_back({{"file", fs::path(sub.pool_file).filename().string()}});
    plane_labels.push_back("planes " + sub.label);
  }
  Json study = settings;
  study["name"] = name;
  study["description"] = "Campaigns from lrcal plan-accuracy on " + base.path;
  study["seed"] = seed;
  study["trials"] = trials;
  // --stop-precision F: the statistics issue's adaptive stopping, trials being the maximum: a
  // campaign stops once every validation mean's SE is within F/2 of it and every validation
  // p95's 95 % interval half-width within F of it (decided every 1000 trials, or trials/10).
  if (stop_precision > 0)
    study["stop_when"] = {{"block", std::max(1, std::min(1000, trials / 10))},
                          {"relative_se", stop_precision / 2},
                          {"p95_relative_halfwidth", stop_precision}};
  if (campaigns.size() == 1) {
    study["selection"]["count"] = campaigns[0].configurations;
    study["noise"]["repetitions"] = campaigns[0].repetitions;
  } else {
    Json axes = {{{"key", "selection.count"}, {"values", counts}},
                 {{"key", "noise.repetitions"}, {"values", reps}}};
    // Campaigns on different planes: each cell its plane list and its pool.
    if (several_subsets) {
      axes.push_back({{"key", "plane"}, {"values", planes}, {"labels", plane_labels}});
      axes.push_back({{"key", "pool"}, {"values", pools}, {"labels", plane_labels}});
    }
    study["sweep"] = {{"combine", "zip"}, {"axes", axes}};
  }
  WriteFileAtomically(path,
                      "# Written by lrcal plan-accuracy (JSON is YAML). Run it with another seed "
                      "to check the\n# campaign: lrcal run " +
                          path + "\n" + study.dump(2) + "\n");
  return path;
}

// The Monte-Carlo figure of each cell of a run: the quantile of the worst axis with its
// distribution-free interval.
void MonteCarloFigures(const std::string& run_dir, const Target& t, double confidence,
                       std::vector<Campaign>* campaigns) {
  TrialStore store(run_dir + "/trials.sqlite");
  const std::vector<StoredCell> cells = store.Cells();
  for (std::size_t i = 0; i < cells.size() && i < campaigns->size(); ++i) {
    std::vector<double> worst;
    store.ForEachTrial(cells[i].id, [&](const TrialRecord& r) {
      if (r.status == TrialStatus::kOk)
        worst.push_back(std::max(
            {r.validation[t.first], r.validation[t.first + 1], r.validation[t.first + 2]}));
    });
    Campaign& c = (*campaigns)[i];
    c.trials = static_cast<long long>(worst.size());
    if (worst.empty()) continue;
    long long low = 0, high = 0;
    QuantileIntervalRanks(c.trials, confidence, 0.95, &low, &high);
    std::vector<double> v = worst;
    c.mc = Quantile(&v, 100 * confidence);
    std::sort(worst.begin(), worst.end());
    c.mc_low = low >= 1 ? worst[low - 1] : NAN;
    c.mc_high = high <= c.trials ? worst[high - 1] : NAN;
  }
}

// The inputs of a plan, from the options.
struct PlanInputs {
  Target target;
  double confidence = 0.95, per_configuration = 0, per_reading = 0, per_plane = 0;
  std::string planes;  // --planes as given, or empty
  int trials = 0, threads = 0;
  double stop_precision = 0;  // 0: every campaign runs `trials`
  std::vector<int> repetitions;
  std::string configurations;  // as given, or empty
  std::string out_dir;
  std::uint64_t seed = 0;
};

PlanInputs ReadInputs(const po::variables_map& vm, const Study& study) {
  PlanInputs in;
  in.target = ParseTarget(vm["target"].as<std::string>());
  in.confidence = vm["confidence"].as<double>();
  if (!(in.confidence > 0 && in.confidence < 1))
    throw InputError("--confidence", "expected a share in (0, 1), e.g. 0.95");
  ParseCost(vm["cost"].as<std::string>(), &in.per_configuration, &in.per_reading, &in.per_plane);
  if (vm.count("planes")) in.planes = vm["planes"].as<std::string>();
  in.trials = vm["trials"].as<int>();
  if (in.trials < 100 || in.trials > 10000000)
    throw InputError("--trials", "expected 100 to 10,000,000 trials per campaign");
  in.stop_precision = vm["stop-precision"].as<double>();
  if (!(in.stop_precision >= 0 && in.stop_precision < 1))
    throw InputError("--stop-precision",
                     "expected 0 (run every trial) or a relative precision in (0, 1), e.g. 0.05");
  in.repetitions = ParseRange(vm["repetitions"].as<std::string>(), "--repetitions", 1);
  if (vm.count("configurations")) in.configurations = vm["configurations"].as<std::string>();
  in.out_dir = vm.count("out") ? vm["out"].as<std::string>() : "output/" + study.name + "-plan";
  in.seed = vm.count("seed") ? static_cast<std::uint64_t>(vm["seed"].as<long long>()) : study.seed;
  in.threads = vm["threads"].as<int>();
  return in;
}

class Planner {
 public:
  Planner(const Study& study, PlanInputs in) : study_(study), in_(std::move(in)) {}

  // The set-up: its validation set, and per plane subset its candidates, written as files (the
  // plan is for these configurations; a confirmation with another seed changes only the noise).
  // A study whose plane is a list of two or more gives candidate planes: every subset with a
  // number of planes in --planes is a choice of its own, with its own pool.
  void PrepareSetUp() {
    fs::create_directories(in_.out_dir);
    const auto base_cell = PrepareCell(study_, study_.cells.at(0));
    validation_file_ = in_.out_dir + "/validation.csv";
    WriteConfigurations(validation_file_, base_cell->validation);
    const Json& planes = study_.base["plane"];
    if (!planes.is_array() || planes.size() < 2) {
      if (!in_.planes.empty())
        throw InputError("--planes",
                         "the set-up has no candidate planes to choose from: give the "
                         "study's plane as a list of two or more planes");
      PlaneSubset all;
      all.pool_file = in_.out_dir + "/pool.csv";
      AddSubset(std::move(all), *base_cell);
    } else {
      const int K = static_cast<int>(planes.size());
      const std::vector<int> sizes =
          ParseRange(in_.planes.empty() ? "1:" + std::to_string(K) : in_.planes, "--planes", 1);
      if (sizes.back() > K)
        throw InputError("--planes", "the set-up has " + std::to_string(K) + " candidate planes");
      for (int size : sizes)
        for (int mask = 1; mask < (1 << K); ++mask)
          if (__builtin_popcount(static_cast<unsigned>(mask)) == size) AddCandidateSubset(mask);
    }
    std::vector<std::string> header = {"configurations", "predicted at 1 reading",
                                       "readings needed", "cost (h)"};
    if (subsets_.size() > 1) header.insert(header.begin(), "planes");
    search_table_ = Table(header,
                          "First-order search (the quantile of the worst axis at one reading per "
                          "configuration)");
  }

  // The first-order search: one prepared cell per plane subset and number of configurations, at
  // one reading.
  void Search() {
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t sub = 0; sub < subsets_.size(); ++sub) {
      std::vector<Campaign> one;
      for (int k : subsets_[sub].counts) {
        Campaign c;
        c.subset = static_cast<int>(sub);
        c.configurations = k;
        c.repetitions = 1;
        one.push_back(c);
      }
      const std::string path = in_.out_dir + "/search" +
                               (subsets_.size() > 1 ? "_" + std::to_string(sub + 1) : "") + ".yaml";
      WriteStudy(study_, path, study_.name + "-search", 1, in_.seed, one, subsets_,
                 validation_file_);
      const Study search = LoadStudy(path);
      for (const Cell& cell : search.cells) {
        const auto ctx = PrepareCell(search, cell);
        AddSearchRow(
            static_cast<int>(sub), cell.typed.select_count,
            WorstAxisQuantile(LinearisedValidationDraws(*ctx, 4000), in_.target, in_.confidence));
      }
    }
    search_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (feasible_.empty())
      throw InputError("--target", "no campaign in the ranges reaches " +
                                       Fixed(in_.target.shown, 4) + " " + in_.target.unit +
                                       " by the first-order prediction; widen --configurations or "
                                       "--repetitions");
    std::stable_sort(feasible_.begin(), feasible_.end(),
                     [](const Campaign& a, const Campaign& b) { return a.cost < b.cost; });
  }

  // Monte Carlo: the cheapest, the same with one reading fewer, and two runner-ups.
  void Confirm() {
    confirm_ = {feasible_[0]};
    confirm_[0].label = "chosen";
    if (feasible_[0].repetitions > 1) {
      Campaign cheaper = feasible_[0];
      --cheaper.repetitions;
      cheaper.predicted = feasible_[0].predicted *
                          std::sqrt(double(feasible_[0].repetitions) / cheaper.repetitions);
      cheaper.cost -= cheaper.configurations * in_.per_reading;
      cheaper.label = "one reading fewer";
      confirm_.push_back(cheaper);
    }
    for (std::size_t i = 1; i < feasible_.size() && i <= 2; ++i) {
      confirm_.push_back(feasible_[i]);
      confirm_.back().label = "runner-up " + std::to_string(i);
    }
    study_path_ = in_.out_dir + "/campaigns.yaml";
    WriteStudy(study_, study_path_, study_.name + "-campaigns", in_.trials, in_.seed, confirm_,
               subsets_, validation_file_, in_.stop_precision);
    RunOptions ro;
    ro.out_dir = run_dir_ = in_.out_dir + "/run";
    ro.threads = in_.threads;
    ro.progress = false;
    const RunResult run = RunStudyAndWriteTables(LoadStudy(study_path_), ro);
    if (!run.complete) throw StorageError("the confirmation run did not finish: " + run_dir_);
    MonteCarloFigures(run_dir_, in_.target, in_.confidence, &confirm_);
  }

  void PrintJson() const {
    Json j;
    j["target"] = {{"metric", in_.target.metric},
                   {"value", in_.target.shown},
                   {"unit", in_.target.unit},
                   {"confidence", in_.confidence}};
    j["search_seconds"] = search_seconds_;
    Json cs = Json::array();
    const auto mm = [](double x) { return std::isnan(x) ? Json() : Json(x * 1e3); };
    for (const Campaign& c : confirm_)
      cs.push_back({{"label", c.label},
                    {"planes", subsets_.size() > 1 ? Json(subsets_[c.subset].names) : Json()},
                    {"configurations", c.configurations},
                    {"repetitions", c.repetitions},
                    {"readings", c.configurations * c.repetitions},
                    {"cost_seconds", c.cost},
                    {"predicted", c.predicted * 1e3},
                    {"monte_carlo", mm(c.mc)},
                    {"monte_carlo_ci", {mm(c.mc_low), mm(c.mc_high)}},
                    {"trials", c.trials},
                    {"meets_target", Meets(c)}});
    j["campaigns"] = cs;
    j["study"] = study_path_;
    j["run"] = run_dir_;
    std::cout << j.dump(2) << "\n";
  }

  void PrintText() const {
    std::cout << search_table_.ToText()
              << "(— : no campaign there: the prediction is not finite, e.g. parameters the "
                 "planes cannot identify, or more readings than --repetitions allows)\n\n";
    const bool stopped = in_.stop_precision > 0;
    std::vector<std::string> header = {"campaign",
                                       "configurations",
                                       "readings each",
                                       "readings",
                                       "cost (h)",
                                       "predicted (" + in_.target.unit + ")",
                                       "Monte Carlo [95 % CI] (" + in_.target.unit + ")",
                                       "meets target"};
    if (stopped) header.push_back("trials");
    const bool planes = subsets_.size() > 1;
    if (planes) header.insert(header.begin() + 1, "planes");
    Table t(header, "Campaigns for " + in_.target.metric + " ≤ " + Fixed(in_.target.shown, 4) +
                        " " + in_.target.unit + " in " + Fixed(100 * in_.confidence, 1) +
                        " % of calibrations (worst axis; " + (stopped ? "up to " : "") +
                        std::to_string(in_.trials) + " Monte-Carlo trials each" +
                        (stopped ? ", stopped at relative precision " + Fixed(in_.stop_precision, 3)
                                 : std::string()) +
                        ")");
    for (const Campaign& c : confirm_) {
      std::vector<std::string> row = {c.label,
                                      std::to_string(c.configurations),
                                      std::to_string(c.repetitions),
                                      std::to_string(c.configurations * c.repetitions),
                                      Fixed(c.cost / 3600, 2),
                                      Fixed(c.predicted * 1e3, 4),
                                      Fixed(c.mc * 1e3, 4) + " [" + Fixed(c.mc_low * 1e3, 4) +
                                          ", " + Fixed(c.mc_high * 1e3, 4) + "]",
                                      Meets(c)};
      if (stopped) row.push_back(std::to_string(c.trials));
      if (planes) row.insert(row.begin() + 1, subsets_[c.subset].label);
      t.AddRow(row);
    }
    std::cout << t.ToText() << "\nsearch " << Fixed(search_seconds_, 1)
              << " s; the campaigns as a study: " << study_path_ << " (run it with another "
              << "seed to check), its run: " << run_dir_ << "\n";
  }

 private:
  // A subset: its pool (drawn for its planes, as a study of them would), the number of
  // parameters and the counts to consider.
  void AddSubset(PlaneSubset subset, const CellContext& cell) {
    WriteConfigurations(subset.pool_file, cell.pool);
    const int n = cell.model->num_parameters(), pool = cell.pool.size();
    subset.num_planes = cell.planes.size();
    subset.counts = ParseRange(in_.configurations.empty()
                                   ? std::to_string(n + 1) + ":" + std::to_string(pool) + ":5"
                                   : in_.configurations,
                               "--configurations", n);
    if (subset.counts.back() > pool)
      throw InputError("--configurations",
                       "at most the pool's " + std::to_string(pool) + " candidates" +
                           (subset.label.empty() ? "" : " on planes " + subset.label) +
                           " (pool.size in the study)");
    subsets_.push_back(std::move(subset));
  }

  // The candidate planes of `mask`: the set-up with just them (their own names, shares and
  // estimate flags), prepared as a study of its own to draw their pool.
  void AddCandidateSubset(int mask) {
    const Json& planes = study_.base["plane"];
    PlaneSubset subset;
    subset.planes = Json::array();
    std::string tag;
    for (int k = 0; k < static_cast<int>(planes.size()); ++k) {
      if (!(mask & (1 << k))) continue;
      subset.planes.push_back(planes[k]);
      subset.names.push_back(planes[k].contains("name") ? planes[k]["name"].get<std::string>()
                                                        : std::to_string(k + 1));
      subset.label += (subset.label.empty() ? "" : "+") + subset.names.back();
      tag += "_" + std::to_string(k + 1);
    }
    subset.pool_file = in_.out_dir + "/pool_planes" + tag + ".csv";
    Json settings = Json::parse(study_.base.dump());
    settings.erase("robot_file_fnv1a");
    settings["robot"] =
        fs::absolute(ResolveRobotPath(study_.base["robot"], study_.folder())).string();
    settings["plane"] = subset.planes;
    settings["name"] = study_.name + "-planes" + tag;
    settings["seed"] = study_.seed;
    settings["trials"] = 1;
    const std::string path = in_.out_dir + "/setup_planes" + tag + ".yaml";
    WriteFileAtomically(path, "# lrcal plan-accuracy: the set-up on planes " + subset.label +
                                  " (JSON is YAML)\n" + settings.dump(2) + "\n");
    const Study setup = LoadStudy(path);
    AddSubset(std::move(subset), *PrepareCell(setup, setup.cells.at(0)));
  }

  void AddSearchRow(int sub, int k, double q1) {
    const PlaneSubset& subset = subsets_[sub];
    const int needed =
        std::isfinite(q1)
            ? std::max(in_.repetitions.front(),
                       static_cast<int>(std::ceil(std::pow(q1 / in_.target.value, 2))))
            : -1;
    const bool ok = needed > 0 && needed <= in_.repetitions.back();
    const double cost = subset.num_planes * in_.per_plane + k * in_.per_configuration +
                        double(k) * needed * in_.per_reading;
    std::vector<std::string> row = {std::to_string(k), Fixed(q1 * 1e3, 4),
                                    ok ? std::to_string(needed) : "—",
                                    ok ? Fixed(cost / 3600, 2) : "—"};
    if (subsets_.size() > 1) row.insert(row.begin(), subset.label);
    search_table_.AddRow(row);
    if (!ok) return;
    Campaign c;
    c.subset = sub;
    c.configurations = k;
    c.repetitions = needed;
    c.predicted = q1 / std::sqrt(double(needed));
    c.cost = cost;
    feasible_.push_back(c);
  }

  // Met when the quantile's whole 95 % interval is at or below the target; not met when the
  // whole interval is above it; otherwise the trials cannot tell.
  std::string Meets(const Campaign& c) const {
    if (std::isnan(c.mc)) return "—";
    if (c.mc_high <= in_.target.value) return "yes";
    if (c.mc_low > in_.target.value) return "no";
    return c.mc <= in_.target.value ? "undecided (estimate below, interval across)"
                                    : "undecided (estimate above, interval across)";
  }

  const Study& study_;
  PlanInputs in_;
  std::string validation_file_, study_path_, run_dir_;
  std::vector<PlaneSubset> subsets_;
  std::vector<Campaign> feasible_, confirm_;
  double search_seconds_ = 0;
  Table search_table_{{}};
};

}  // namespace

int PlanAccuracyCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal plan-accuracy options");
  o.add_options()("study", po::value<std::string>(),
                  "study file of the set-up (its base settings)")(
      "target", po::value<std::string>()->required(),
      "e.g. rms_pos=0.05mm: the quantile at --confidence of the largest per-axis RMS position "
      "error over the validation poses must not exceed it (also rms_ori, max_pos, max_ori)")(
      "confidence", po::value<double>()->default_value(0.95), "share of calibrations that meet it")(
      "configurations", po::value<std::string>(),
      "FIRST:LAST[:STEP] configurations to consider (default: parameters+1 to the pool size, "
      "step 5)")("repetitions", po::value<std::string>()->default_value("1:100"),
                 "FIRST:LAST readings per configuration to consider")(
      "cost", po::value<std::string>()->default_value("configuration=30s,reading=1s"),
      "time per configuration (move) and per reading, and per plane set up (plane=600s)")(
      "planes", po::value<std::string>(),
      "FIRST:LAST candidate planes a campaign may use, when the study's plane is a list of two "
      "or more (default: 1 to all; every subset of those sizes is considered)")(
      "trials", po::value<int>()->default_value(10000),
      "Monte-Carlo trials per confirmed campaign")(
      "stop-precision", po::value<double>()->default_value(0.0),
      "stop each confirmed campaign once its validation means (SE) and p95s (95 % interval "
      "half-width) are known to this relative precision; --trials is then the maximum")(
      "seed", po::value<long long>(), "seed of the confirmation runs (default: the study's)")(
      "out", po::value<std::string>(), "folder for the confirmation study and run")(
      "threads", po::value<int>()->default_value(0), "threads (0: all cores)")(
      "format", po::value<std::string>()->default_value("text"), "text or json");
  po::positional_options_description pos;
  pos.add("study", 1);
  po::variables_map vm;
  if (!Parse("plan-accuracy", "[STUDY.yaml] --target rms_pos=0.05mm [options]", o, args, &vm, &pos))
    return 0;
  const Study study =
      LoadStudy(ResolveStudyPath(vm.count("study") ? vm["study"].as<std::string>() : "paper"));
  Planner planner(study, ReadInputs(vm, study));
  planner.PrepareSetUp();
  planner.Search();
  planner.Confirm();
  if (ResolveFormat(vm) == Format::kJson) {
    planner.PrintJson();
  } else {
    planner.PrintText();
  }
  return 0;
}

}  // namespace lrcal::cli
