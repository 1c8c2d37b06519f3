#include "lrcal/report/accuracy_plan.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include "lrcal/core/descriptive_statistics.h"
#include "lrcal/core/hash.h"
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/report/run_tables.h"
#include "lrcal/study/prepared_cell.h"
#include "lrcal/study/runner.h"
#include "lrcal/study/trial_store.h"

namespace lrcal {

namespace {

// What a plan is on, in the tables' and notes' words.
const char* PlanBasisPhrase(PlanBasis basis) {
  return basis == PlanBasis::kTotal ? "the total" : "the reading noise's part";
}

namespace fs = std::filesystem;

const SettingSpec& Spec(const char* name) {
  for (const SettingSpec& s : AccuracyPlanOptions::Settings())
    if (std::string(s.name) == name) return s;
  throw std::logic_error(std::string("no plan setting ") + name);
}

[[noreturn]] void Refuse(const char* name, const std::string& problem) {
  throw SettingError(Spec(name), problem);
}

// "a:b" or "a:b:step" (whole numbers).
std::vector<int> ParseRange(const std::string& text, const char* setting, int lo_limit) {
  int a = 0, b = 0, step = 1;
  char c1 = 0, c2 = 0;
  std::istringstream in(text);
  in >> a >> c1 >> b;
  if (in && !in.eof() && in.peek() == ':') in >> c2 >> step;
  if (!in || c1 != ':' || a < lo_limit || b < a || step < 1 || !in.eof())
    Refuse(setting, "expected FIRST:LAST or FIRST:LAST:STEP with " + std::to_string(lo_limit) +
                        " <= FIRST <= LAST, got '" + text + "'");
  std::vector<int> out;
  for (int v = a; v <= b; v += step) out.push_back(v);
  if (out.back() != b) out.push_back(b);
  return out;
}

// The quantile at `confidence` of the largest per-axis component of the target metric.
double WorstAxisQuantile(const Eigen::MatrixXd& draws, const AccuracyTarget& t, double confidence) {
  std::vector<double> worst(static_cast<std::size_t>(draws.rows()));
  for (Eigen::Index d = 0; d < draws.rows(); ++d)
    worst[d] = std::max({draws(d, t.first()), draws(d, t.first() + 1), draws(d, t.first() + 2)});
  return Quantile(&worst, 100 * confidence);
}

// The first index of `reps` (ascending) at which `meets` holds, the quantile falling as the
// readings grow; none when the last does not. It checks the index the guess (in readings) falls
// on and its neighbour first, then bisects: two or three evaluations when the guess is right.
template <typename Meets>
std::optional<std::size_t> FirstMeeting(const std::vector<int>& reps, double guess, Meets meets) {
  std::size_t lo = 0, hi = reps.size() - 1, i = 0;  // the answer is in [lo, hi]
  while (i < hi && reps[i] < guess) ++i;
  if (meets(i)) {
    hi = i;
    if (i > 0 && !meets(i - 1)) return i;
  } else {
    if (i == hi || !meets(hi)) return std::nullopt;
    lo = i + 1;
    if (meets(lo)) return lo;
  }
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (meets(mid)) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  return hi;
}

// A study file for the set-up with the given cells (zip of configurations and repetitions). The
// candidates and the validation set are the files written beside it, so that another seed
// changes only the noise.
std::string WriteStudy(const Study& base, const std::string& path, const std::string& name,
                       int trials, std::uint64_t seed,
                       const std::vector<PlannedCampaign>& campaigns,
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
  for (const PlannedCampaign& c : campaigns) {
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
void MonteCarloFigures(const std::string& run_dir, const AccuracyTarget& t, double confidence,
                       std::vector<PlannedCampaign>* campaigns) {
  TrialStore store(run_dir + "/trials.sqlite");
  const std::vector<StoredCell> cells = store.Cells();
  for (std::size_t i = 0; i < cells.size() && i < campaigns->size(); ++i) {
    std::vector<double> worst;
    store.ForEachTrial(cells[i].id, [&](const TrialRecord& r) {
      if (r.status == TrialStatus::kOk)
        worst.push_back(std::max(
            {r.validation[t.first()], r.validation[t.first() + 1], r.validation[t.first() + 2]}));
    });
    PlannedCampaign& c = (*campaigns)[i];
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

// The plan's settings resolved against the study.
struct PlanInputs {
  AccuracyTarget target;
  double confidence = 0.95, per_configuration = 0, per_reading = 0, per_plane = 0;
  std::string planes;  // as given, or empty
  int trials = 0, threads = 0;
  double stop_precision = 0;  // 0: every campaign runs `trials`
  std::vector<int> repetitions;
  std::string configurations;  // as given, or empty
  std::string out_dir;
  std::uint64_t seed = 0;
  PlanBasis plan_on = PlanBasis::kTotal;
};

// What a plan's results depend on (not its threads): kept in its folder as plan.json.
Json PlanSettings(const PlanInputs& in, const Study& study) {
  return {{"study", {{"name", study.name}, {"base", study.base}}},
          {"target", {{"metric", in.target.name()}, {"value", in.target.value}}},
          {"confidence", in.confidence},
          {"cost",
           {{"configuration", in.per_configuration},
            {"reading", in.per_reading},
            {"plane", in.per_plane}}},
          {"planes", in.planes},
          {"configurations", in.configurations},
          {"repetitions", in.repetitions},
          {"trials", in.trials},
          {"stop_precision", in.stop_precision},
          {"seed", in.seed},
          {"plan_on", NameOf(kPlanBasisNames, in.plan_on)}};
}

PlanInputs Resolve(const AccuracyPlanOptions& o, const Study& study) {
  o.Validate();
  PlanInputs in;
  in.target = o.target;
  in.confidence = o.confidence;
  in.per_configuration = o.cost.per_configuration;
  in.per_reading = o.cost.per_reading;
  in.per_plane = o.cost.per_plane;
  in.planes = o.planes;
  in.trials = o.trials;
  in.threads = o.threads;
  in.stop_precision = o.stop_precision;
  in.repetitions = ParseRange(o.repetitions, "repetitions", 1);
  in.configurations = o.configurations;
  in.seed = o.seed ? *o.seed : study.seed;
  in.plan_on = o.plan_on;
  // The default folder is named by the plan's settings: another seed, cost or target plans in a
  // folder of its own instead of being refused by the last plan's.
  in.out_dir = o.out_dir.empty() ? "output/" + study.name + "-plan-" +
                                       HashHex(PlanSettings(in, study).dump()).substr(0, 8)
                                 : o.out_dir;
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
    CheckFolder();
    fs::create_directories(in_.out_dir);
    WriteFileAtomically(in_.out_dir + "/plan.json", PlanSettings(in_, study_).dump(2) + "\n");
    const PreparedCell base_cell = PreparedCell::Prepare(study_, study_.cells.at(0));
    validation_file_ = in_.out_dir + "/validation.csv";
    WritePoses(validation_file_, base_cell.validation());
    const Json& planes = study_.base["plane"];
    if (!planes.is_array() || planes.size() < 2) {
      if (!in_.planes.empty())
        Refuse("planes",
               "the set-up has no candidate planes to choose from: give the study's plane as a "
               "list of two or more planes");
      PlaneSubset all;
      all.pool_file = in_.out_dir + "/pool.csv";
      AddSubset(std::move(all), base_cell);
    } else {
      const int K = static_cast<int>(planes.size());
      const std::vector<int> sizes =
          ParseRange(in_.planes.empty() ? "1:" + std::to_string(K) : in_.planes, "planes", 1);
      if (sizes.back() > K)
        Refuse("planes", "the set-up has " + std::to_string(K) + " candidate planes");
      for (int size : sizes)
        for (int mask = 1; mask < (1 << K); ++mask)
          if (__builtin_popcount(static_cast<unsigned>(mask)) == size) AddCandidateSubset(mask);
    }
    const std::string unit = " (" + in_.target.unit() + ")";
    std::vector<std::string> header = {"configurations",    "reading noise at 1 reading" + unit,
                                       "held terms" + unit, "readings needed",
                                       "total" + unit,      "cost (h)"};
    if (subsets_.size() > 1) header.insert(header.begin(), "planes");
    search_table_ = Table(
        header, std::string("First-order search (the quantile of the worst axis; planned on ") +
                    PlanBasisPhrase(in_.plan_on) +
                    "; held terms and total at the readings needed, or at the most readings "
                    "considered)");
  }

  // The first-order search: one prepared cell per plane subset and number of configurations, at
  // one reading.
  void Search() {
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t sub = 0; sub < subsets_.size(); ++sub) {
      std::vector<PlannedCampaign> one;
      for (int k : subsets_[sub].counts) {
        PlannedCampaign c;
        c.subset = static_cast<int>(sub);
        c.configurations = k;
        c.repetitions = 1;
        one.push_back(c);
      }
      const std::string path = in_.out_dir + "/search" +
                               (subsets_.size() > 1 ? "_" + std::to_string(sub + 1) : "") + ".yaml";
      WriteStudy(study_, path, study_.name + "-search", 1, in_.seed, one, subsets_,
                 validation_file_);
      search_paths_.push_back(path);
      const Study search = LoadStudy(path);
      for (const Cell& cell : search.cells) {
        const PreparedCell prepared = PreparedCell::Prepare(search, cell);
        if (&cell == &search.cells.front()) NoteHeldTerms(prepared);  // the same for every count
        AddSearchRow(static_cast<int>(sub), cell.typed.select_count, prepared);
      }
    }
    search_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (feasible_.empty()) RefuseUnreachable();
    std::stable_sort(
        feasible_.begin(), feasible_.end(),
        [](const Candidate& a, const Candidate& b) { return a.campaign.cost < b.campaign.cost; });
  }

  // The chosen campaign's statement by source: its search cell prepared again (the same design),
  // at its readings.
  void StateChosen() {
    const PlannedCampaign& c = feasible_[0].campaign;
    const Study search = LoadStudy(search_paths_.at(c.subset));
    for (const Cell& cell : search.cells)
      if (cell.typed.select_count == c.configurations) {
        chosen_statement_ =
            PreparedCell::Prepare(search, cell).StatedValidationAccuracy(c.repetitions);
        return;
      }
  }

  // Monte Carlo: the cheapest, the same with one reading fewer, and two runner-ups.
  void Confirm() {
    confirm_ = {feasible_[0].campaign};
    confirm_[0].label = "chosen";
    if (feasible_[0].campaign.repetitions > 1) {
      confirm_.push_back(feasible_[0].fewer);
      confirm_.back().label = "one reading fewer";
    }
    for (std::size_t i = 1; i < feasible_.size() && i <= 2; ++i) {
      confirm_.push_back(feasible_[i].campaign);
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

  // The plan: what was searched and confirmed.
  AccuracyPlan Finish(const AccuracyPlanOptions& options) && {
    AccuracyPlan plan;
    plan.options = options;
    plan.search_table = std::move(search_table_);
    plan.subsets = std::move(subsets_);
    plan.campaigns = std::move(confirm_);
    plan.search_seconds = search_seconds_;
    plan.chosen_statement = std::move(chosen_statement_);
    plan.defaulted = std::move(defaulted_);
    plan.exact = std::move(exact_);
    plan.study_path = study_path_;
    plan.run_dir = run_dir_;
    return plan;
  }

 private:
  // A folder that holds a plan with other settings is refused before any work (its
  // confirmation run would refuse them after the search); the same settings go on (the run
  // resumes).
  void CheckFolder() const {
    const std::string path = in_.out_dir + "/plan.json";
    if (!fs::exists(path)) return;
    const std::vector<std::string> changes =
        DiffJson(ReadJsonFile(path), PlanSettings(in_, study_));
    if (changes.empty()) return;
    std::string what;
    for (const std::string& c : changes) what += "\n  " + c;
    Refuse("out", "'" + in_.out_dir + "' holds a plan with other settings; changed:" + what +
                      "\ngive another folder, or leave it out (each plan's default folder "
                      "is named by its settings)");
  }

  // A subset: its pool (drawn for its planes, as a study of them would), the number of
  // parameters and the counts to consider.
  void AddSubset(PlaneSubset subset, const PreparedCell& cell) {
    WriteConfigurations(subset.pool_file, cell.pool());
    const int n = cell.num_parameters(), pool = cell.pool().size();
    subset.num_planes = cell.num_planes();
    subset.counts = ParseRange(in_.configurations.empty()
                                   ? std::to_string(n + 1) + ":" + std::to_string(pool) + ":5"
                                   : in_.configurations,
                               "configurations", n);
    if (subset.counts.back() > pool)
      Refuse("configurations", "at most the pool's " + std::to_string(pool) + " candidates" +
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
    AddSubset(std::move(subset), PreparedCell::Prepare(setup, setup.cells.at(0)));
  }

  // A campaign found by the search, with the same campaign one reading fewer per configuration.
  struct Candidate {
    PlannedCampaign campaign, fewer;
  };

  // The quantiles of each part of a prepared search cell's first-order prediction at R readings.
  struct Quantiles {
    double data = NAN, held = NAN, total = NAN;
  };
  Quantiles QuantilesAt(const PreparedCell& cell, int R) const {
    constexpr int kDraws = 4000;
    const FirstOrderDraws draws = cell.LinearisedValidationDraws(kDraws, R);
    return {WorstAxisQuantile(draws.data, in_.target, in_.confidence),
            WorstAxisQuantile(draws.held, in_.target, in_.confidence),
            WorstAxisQuantile(draws.total, in_.target, in_.confidence)};
  }
  double Basis(const Quantiles& q) const {
    return in_.plan_on == PlanBasis::kTotal ? q.total : q.data;
  }

  // The held terms that took a default tolerance and the frame terms taken as exact, in the order
  // first met.
  void NoteHeldTerms(const PreparedCell& cell) {
    const std::optional<AccuracyPrediction> stated = cell.StatedValidationAccuracy(1);
    if (!stated) return;
    const auto add = [](std::vector<std::string>* to, const std::vector<std::string>& names) {
      for (const std::string& name : names)
        if (std::find(to->begin(), to->end(), name) == to->end()) to->push_back(name);
    };
    add(&defaulted_, stated->defaulted);
    add(&exact_, stated->exact);
  }

  // One row of the search: the fewest readings whose quantile of the plan's basis meets the
  // target (none if the range's last does not), the held terms' part and the total there. The
  // search starts where the quantiles' model q² ≈ q₁²/R + q_held² puts the answer (exact for the
  // data part without priors) and checks it and its neighbour; a bisection over the range
  // settles anything else (the quantile falls as R grows).
  void AddSearchRow(int sub, int k, const PreparedCell& cell) {
    const PlaneSubset& subset = subsets_[sub];
    const std::vector<int>& reps = in_.repetitions;
    std::map<int, Quantiles> known;
    const auto at = [&](int R) -> const Quantiles& {
      auto it = known.find(R);
      if (it == known.end()) it = known.emplace(R, QuantilesAt(cell, R)).first;
      return it->second;
    };
    const auto meets = [&](std::size_t i) {
      const double q = Basis(at(reps[i]));
      return std::isfinite(q) && q <= in_.target.value;
    };
    const Quantiles& one = at(1);
    const double q1 = one.data;
    const double target2 = in_.target.value * in_.target.value;
    const double held = in_.plan_on == PlanBasis::kTotal ? one.held : 0.0;
    const double guess = target2 > held * held ? q1 * q1 / (target2 - held * held) : reps.back();
    const std::optional<std::size_t> first = FirstMeeting(reps, guess, meets);
    const bool ok = first.has_value();
    const int needed = ok ? reps[*first] : -1;
    const Quantiles& there = at(ok ? needed : reps.back());
    if (std::isfinite(there.held)) smallest_held_ = std::min(smallest_held_, there.held);
    const double cost = subset.num_planes * in_.per_plane + k * in_.per_configuration +
                        double(k) * needed * in_.per_reading;
    std::vector<std::string> row = {std::to_string(k),           Fixed(q1 * 1e3, 4),
                                    Fixed(there.held * 1e3, 4),  ok ? std::to_string(needed) : "—",
                                    Fixed(there.total * 1e3, 4), ok ? Fixed(cost / 3600, 2) : "—"};
    if (subsets_.size() > 1) row.insert(row.begin(), subset.label);
    search_table_.AddRow(row);
    if (!ok) return;
    Candidate c;
    c.campaign.subset = sub;
    c.campaign.configurations = k;
    c.campaign.repetitions = needed;
    c.campaign.predicted_data = there.data;
    c.campaign.predicted_total = there.total;
    c.campaign.predicted = Basis(there);
    c.campaign.cost = cost;
    if (needed > 1) {
      c.fewer = c.campaign;
      --c.fewer.repetitions;
      const Quantiles& q = at(c.fewer.repetitions);
      c.fewer.predicted_data = q.data;
      c.fewer.predicted_total = q.total;
      c.fewer.predicted = Basis(q);
      c.fewer.cost -= k * in_.per_reading;
    }
    feasible_.push_back(c);
  }

  // No campaign in the ranges meets the target: say why, and what would.
  [[noreturn]] void RefuseUnreachable() const {
    std::ostringstream v;
    v << in_.target.shown();  // 6 significant digits
    std::string why = "no campaign in the ranges reaches " + v.str() + " " + in_.target.unit() +
                      " by the first-order prediction";
    if (in_.plan_on == PlanBasis::kTotal && smallest_held_ > in_.target.value) {
      why += " of the total: the terms the calibration holds at nominal give " +
             Fixed(smallest_held_ * 1e3, 4) + " " + in_.target.unit() +
             " on their own at best (the search table's held terms)";
      if (!defaulted_.empty()) {
        why += ", with lrcal's default tolerances (" + DefaultTolerances{}.ToString() + ") for";
        for (const std::string& name : defaulted_) why += " " + name;
      }
      why +=
          "; estimate them (identification.estimate_plane, identification.estimate_ranger), "
          "give their tolerances (the robot file's tolerances:, identification.prior_sigma), "
          "or plan on the reading noise's part alone ({0:data})";
    } else {
      why += "; widen the {1} or {2} to consider";
    }
    throw SettingError(Spec("target"), why,
                       {Spec("plan_on"), Spec("configurations"), Spec("repetitions")});
  }

  const Study& study_;
  PlanInputs in_;
  std::string validation_file_, study_path_, run_dir_;
  std::vector<PlaneSubset> subsets_;
  std::vector<Candidate> feasible_;
  std::vector<PlannedCampaign> confirm_;
  std::vector<std::string> defaulted_, exact_;
  std::vector<std::string> search_paths_;  // the search study of each plane subset
  std::optional<AccuracyPrediction> chosen_statement_;
  double smallest_held_ = std::numeric_limits<double>::infinity();
  double search_seconds_ = 0;
  Table search_table_{{}};
};

}  // namespace

const std::vector<SettingSpec>& AccuracyPlanOptions::Settings() {
  static const std::vector<SettingSpec> specs = {
      {"plan", "target", "target", "", 1, "", 0, kInf, false, false, "", "",
       "e.g. rms_pos=0.05mm: the quantile at the confidence of the worst axis must not exceed it"},
      {"plan", "confidence", "confidence", "", 1, "", 0, 1, true, false, "", "",
       "share of calibrations that meet the target", nullptr, true},
      {"plan", "cost", "cost", "", 1, "", 0, kInf, false, false, "", "",
       "time per configuration, per reading and per plane set up"},
      {"plan", "configurations", "configurations", "", 1, "", 0, kInf, false, false, "", "",
       "FIRST:LAST[:STEP] configurations to consider"},
      {"plan", "repetitions", "repetitions", "", 1, "", 0, kInf, false, false, "", "",
       "FIRST:LAST[:STEP] readings per configuration to consider"},
      {"plan", "planes", "planes", "", 1, "", 0, kInf, false, false, "", "",
       "FIRST:LAST candidate planes a campaign may use"},
      {"plan", "trials", "trials", "", 1, "", 100, 1e7, false, true, "trials per campaign", "",
       "Monte-Carlo trials per confirmed campaign"},
      {"plan", "stop_precision", "stop_precision", "", 1, "", 0, 1, false, false, "", "",
       "stop each confirmed campaign once its validation means (SE) and p95s (95 % interval "
       "half-width) are known to this relative precision (0: run every trial; trials is then "
       "the maximum)",
       nullptr, true},
      {"plan", "out_dir", "out", "", 1, "", 0, kInf, false, false, "", "",
       "folder for the confirmation study and run", "out_dir"},
      {"plan", "plan_on", "plan_on", "", 1, "", 0, kInf, false, false, "", "",
       "total (the reading noise's part plus the terms held at nominal, at their tolerances) "
       "or data (the reading noise's part alone)"},
  };
  return specs;
}

const std::vector<SettingField<AccuracyPlanOptions>>& AccuracyPlanOptions::NumericSettings() {
  using O = AccuracyPlanOptions;
  static const std::vector<SettingField<O>> fields = {
      {Spec("confidence"), &O::confidence},
      {Spec("trials"), nullptr, &O::trials},
      {Spec("stop_precision"), &O::stop_precision},
  };
  return fields;
}

void AccuracyPlanOptions::Validate() const {
  if (!(target.value > 0) || !std::isfinite(target.value))
    Refuse("target", "expected a target > 0 with its unit, e.g. rms_pos=0.05mm");
  CheckSettings(*this, NumericSettings());
  for (double c : {cost.per_configuration, cost.per_reading, cost.per_plane})
    if (!(c >= 0) || !std::isfinite(c)) Refuse("cost", "expected costs >= 0 (s)");
  ParseRange(repetitions, "repetitions", 1);
  if (threads < 0) throw InputError("threads", "expected 0 (all cores) or more");
}

PlanBasis ParsePlanBasis(const std::string& text) {
  PlanBasis basis = PlanBasis::kTotal;
  if (!TryParseName(kPlanBasisNames, text, &basis))
    Refuse("plan_on", "expected " + NameList(kPlanBasisNames) + ", got '" + text + "'");
  return basis;
}

AccuracyTarget AccuracyTarget::Parse(const std::string& text) {
  const auto eq = text.find('=');
  const std::string expected =
      "expected METRIC=VALUE with a unit, e.g. rms_pos=0.05mm or rms_ori=0.1mrad (metrics " +
      NameList(kValidationMetricNames) + "), got '" + text + "'";
  if (eq == std::string::npos) Refuse("target", expected);
  AccuracyTarget t;
  if (!TryParseName(kValidationMetricNames, text.substr(0, eq), &t.metric))
    Refuse("target", expected);
  std::string value = text.substr(eq + 1);
  const std::string unit = t.unit();
  if (value.size() > unit.size() &&
      value.compare(value.size() - unit.size(), unit.size(), unit) == 0)
    value.resize(value.size() - unit.size());
  else
    Refuse("target", "the value needs its unit (" + unit + "): " + expected);
  char* end = nullptr;
  const double shown = std::strtod(value.c_str(), &end);
  if (value.empty() || *end != '\0' || !(shown > 0) || !std::isfinite(shown))
    Refuse("target", expected);
  t.value = shown * 1e-3;
  return t;
}

CampaignCosts CampaignCosts::Parse(const std::string& text) {
  const std::string expected =
      "expected configuration=SECONDSs,reading=SECONDSs[,plane=SECONDSs], e.g. "
      "configuration=30s,reading=1s,plane=600s, got '" +
      text + "'";
  CampaignCosts costs;
  costs.per_plane = 0;
  std::istringstream in(text);
  std::string part;
  bool got_c = false, got_r = false;
  while (std::getline(in, part, ',')) {
    const auto eq = part.find('=');
    if (eq == std::string::npos || part.back() != 's') Refuse("cost", expected);
    const std::string key = part.substr(0, eq), value = part.substr(eq + 1, part.size() - eq - 2);
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !(v >= 0)) Refuse("cost", expected);
    if (key == "configuration") {
      costs.per_configuration = v;
      got_c = true;
    } else if (key == "reading") {
      costs.per_reading = v;
      got_r = true;
    } else if (key == "plane") {
      costs.per_plane = v;
    } else {
      Refuse("cost", expected);
    }
  }
  if (!got_c || !got_r) Refuse("cost", expected);
  return costs;
}

std::string CampaignCosts::ToString() const {
  std::ostringstream out;
  out << "configuration=" << per_configuration << "s,reading=" << per_reading << "s";
  if (per_plane > 0) out << ",plane=" << per_plane << "s";
  return out.str();
}

// Met when the quantile's whole 95 % interval is at or below the target; not met when the
// whole interval is above it; otherwise the trials cannot tell.
std::string AccuracyPlan::Meets(const PlannedCampaign& c) const {
  const double target = options.target.value;
  if (std::isnan(c.mc)) return "—";
  if (c.mc_high <= target) return "yes";
  if (c.mc_low > target) return "no";
  return c.mc <= target ? "undecided (estimate below, interval across)"
                        : "undecided (estimate above, interval across)";
}

ResultJson AccuracyPlan::ToJson() const {
  ResultJson j;
  j["target"] = {{"metric", std::string(options.target.name())},
                 {"value", options.target.shown()},
                 {"unit", options.target.unit()},
                 {"confidence", options.confidence}};
  j["search_seconds"] = search_seconds;
  j["plan_on"] = NameOf(kPlanBasisNames, options.plan_on);
  j["defaulted"] = defaulted;
  j["taken_as_exact"] = exact;
  ResultJson cs = ResultJson::array();
  const auto mm = [](double x) { return std::isnan(x) ? ResultJson() : ResultJson(x * 1e3); };
  for (const PlannedCampaign& c : campaigns)
    cs.push_back(
        {{"label", c.label},
         {"planes", subsets.size() > 1 ? ResultJson(subsets[c.subset].names) : ResultJson()},
         {"configurations", c.configurations},
         {"repetitions", c.repetitions},
         {"readings", c.configurations * c.repetitions},
         {"cost_seconds", c.cost},
         {"predicted", c.predicted * 1e3},
         {"predicted_total", c.predicted_total * 1e3},
         {"predicted_data", c.predicted_data * 1e3},
         {"monte_carlo", mm(c.mc)},
         {"monte_carlo_ci", {mm(c.mc_low), mm(c.mc_high)}},
         {"trials", c.trials},
         {"meets_target", Meets(c)}});
  j["campaigns"] = cs;
  j["chosen_sources"] =
      chosen_statement ? AccuracySourcesJson(chosen_statement->sources) : ResultJson();
  j["study"] = study_path;
  j["run"] = run_dir;
  return j;
}

namespace {

// What the search table holds and leaves out, and which held terms took a default tolerance.
std::string SearchNotes(const AccuracyPlan& plan) {
  std::ostringstream out;
  out << "(— : no campaign there: the prediction is not finite, e.g. parameters the "
         "planes cannot identify, or more readings than plan.repetitions allows)\n"
      << "reading noise: the estimated parameters' covariance; held terms: every term the "
         "calibration holds at nominal (fixed parameters, plane and ranger terms not estimated, "
         "a base or tool term with a tolerance), each at its tolerance (identification."
         "prior_sigma, else the robot file's tolerances:, else lrcal's defaults); total: both "
         "(README: What a calibration cannot see). The plan is on "
      << PlanBasisPhrase(plan.options.plan_on)
      << (plan.options.plan_on == PlanBasis::kTotal
              ? " (or, with plan_on data, on the reading noise's part alone)"
              : " alone: the held terms may make the calibrated arm less accurate than planned")
      << ". The Monte-Carlo confirmation simulates the study's truth: it has every error that "
         "truth has and no other, so the held terms count there only as far as the truth moves "
         "them.\n";
  if (!plan.defaulted.empty()) {
    out << "warning: no tolerance known for " << plan.defaulted.size()
        << " held terms; the stated defaults (" << plan.defaults.ToString() << ") were used for:";
    for (const std::string& name : plan.defaulted) out << " " << name;
    out << "\n";
  }
  if (!plan.exact.empty())
    out << "note: taken as exact (no tolerance given, not estimated): "
        << ExactFramesText(plan.exact) << "\n";
  return out.str();
}

}  // namespace

std::string AccuracyPlan::ToText() const {
  std::ostringstream out;
  out << search_table.ToText() << SearchNotes(*this);
  out << "\n";
  const bool stopped = options.stop_precision > 0;
  std::vector<std::string> header = {"campaign",
                                     "configurations",
                                     "readings each",
                                     "readings",
                                     "cost (h)",
                                     "predicted total (" + options.target.unit() + ")",
                                     "predicted reading noise (" + options.target.unit() + ")",
                                     "Monte Carlo [95 % CI] (" + options.target.unit() + ")",
                                     "meets target (Monte Carlo)"};
  if (stopped) header.push_back("trials");
  const bool planes = subsets.size() > 1;
  if (planes) header.insert(header.begin() + 1, "planes");
  Table t(header,
          "Campaigns for " + std::string(options.target.name()) + " ≤ " +
              Fixed(options.target.shown(), 4) + " " + options.target.unit() + " in " +
              Fixed(100 * options.confidence, 1) + " % of calibrations (worst axis; " +
              (stopped ? "up to " : "") + std::to_string(options.trials) +
              " Monte-Carlo trials each" +
              (stopped ? ", stopped at relative precision " + Fixed(options.stop_precision, 3)
                       : std::string()) +
              "; planned on " + PlanBasisPhrase(options.plan_on) +
              ", Monte Carlo of the study's truth)");
  for (const PlannedCampaign& c : campaigns) {
    std::vector<std::string> row = {c.label,
                                    std::to_string(c.configurations),
                                    std::to_string(c.repetitions),
                                    std::to_string(c.configurations * c.repetitions),
                                    Fixed(c.cost / 3600, 2),
                                    Fixed(c.predicted_total * 1e3, 4),
                                    Fixed(c.predicted_data * 1e3, 4),
                                    Fixed(c.mc * 1e3, 4) + " [" + Fixed(c.mc_low * 1e3, 4) + ", " +
                                        Fixed(c.mc_high * 1e3, 4) + "]",
                                    Meets(c)};
    if (stopped) row.push_back(std::to_string(c.trials));
    if (planes) row.insert(row.begin() + 1, subsets[c.subset].label);
    t.AddRow(row);
  }
  out << t.ToText();
  if (options.plan_on == PlanBasis::kTotal)
    out << "The Monte Carlo has the held terms' errors only as far as the study's truth has them: "
           "it confirms the rest; the held terms' part of the total is first order, from their "
           "tolerances.\n";
  if (chosen_statement)
    out << "\nThe chosen campaign's total by source (first order, "
        << std::to_string(campaigns.empty() ? 0 : campaigns[0].repetitions)
        << " readings per configuration, over the validation poses):\n"
        << AccuracySourceTable(*chosen_statement);
  out << "\nsearch " << Fixed(search_seconds, 1) << " s; the campaigns as a study: " << study_path
      << " (run it with another "
      << "seed to check), its run: " << run_dir << "\n";
  return out.str();
}

AccuracyPlan PlanAccuracy(const Study& study, const AccuracyPlanOptions& options) {
  Planner planner(study, Resolve(options, study));
  planner.PrepareSetUp();
  planner.Search();
  planner.StateChosen();
  planner.Confirm();
  return std::move(planner).Finish(options);
}

}  // namespace lrcal
