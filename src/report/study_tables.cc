#include "lrcal/report/study_tables.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include "lrcal/core/descriptive_statistics.h"
#include "lrcal/core/error.h"
#include "lrcal/core/text_document.h"
#include "lrcal/core/text_table.h"
#include "lrcal/kinematics/validation_metric.h"
#include "lrcal/measurement/parameter_set.h"
#include "lrcal/paper/paper_case.h"
#include "lrcal/study/sensitivity.h"

namespace lrcal {

namespace {

using Rows = std::vector<std::vector<std::string>>;

const char* MetricName(int m) {
  return NameOf(kValidationMetricNames, static_cast<ValidationMetric>(m));
}
const char* kMetricTitles[4] = {"RMS pos (mm)", "RMS ori (mrad)", "max pos (mm)", "max ori (mrad)"};
const auto& kAxes = kAxisNames;

std::string MeanRange(const Distribution& d, double scale) {
  if (d.n == 0) return "—";
  return Fixed(d.mean * scale) + " ± " + Fixed(d.mean_se * scale) + " [" + Fixed(d.p5 * scale) +
         ", " + Fixed(d.p95 * scale) + "]";
}

// A number of a CSV column that may be unavailable (too few trials): empty then.
std::string CsvValue(double x, int digits = 6) { return std::isnan(x) ? "" : Fixed(x, digits); }

std::string UnitOf(const std::string& parameter) { return DisplayUnitOf(parameter).unit; }

Json DistJson(const Distribution& d, double scale) {
  auto v = [&](double x) { return std::isnan(x) ? Json() : Json(x * scale); };
  auto ci = [&](const QuantileInterval& q) { return Json::array({v(q.low), v(q.high)}); };
  return {{"n", d.n},
          {"mean", v(d.mean)},
          {"mean_se", v(d.mean_se)},
          {"std", v(d.std)},
          {"std_se", v(d.std_se)},
          {"p5", v(d.p5)},
          {"p5_ci", ci(d.p5_ci)},
          {"p50", v(d.p50)},
          {"p50_ci", ci(d.p50_ci)},
          {"p95", v(d.p95)},
          {"p95_ci", ci(d.p95_ci)},
          {"max", v(d.max)},
          {"max_bounds_p95", d.n ? Json(d.max_bounds_p95) : Json()}};
}

Json MatrixJson(const Eigen::MatrixXd& m) {
  Json j = Json::array();
  for (int r = 0; r < m.rows(); ++r) {
    Json row = Json::array();
    for (int c = 0; c < m.cols(); ++c) row.push_back(std::isnan(m(r, c)) ? Json() : Json(m(r, c)));
    j.push_back(row);
  }
  return j;
}

bool SameDistribution(const Distribution& a, const Distribution& b) {
  return a.n == b.n && a.mean == b.mean && a.p5 == b.p5 && a.p95 == b.p95;
}

// ---------------------------------------------------------------------------------------------
// The paper's published numbers in our distributions (paper cells only): the values are placed
// while a cell is summarised (SummaryProbes), so no cell's values are ever held in memory.

int PaperCaseOf(const StoredCell& cell) {
  const int paper_case = Json::parse(cell.settings).value("paper_case", 0);
  return paper_case >= 1 && paper_case <= 2 ? paper_case : 0;
}

// Identified parameters: published error = published Δ − the cell's recorded true Δ (the robot
// file's errors × truth.scale, stored with the cell: no robot file is read after the run). NaN
// where the paper has no value.
double PublishedError(const StoredCell& cell, int paper_case, const std::string& name) {
  const std::vector<double>& truth = cell.truth_errors;
  const int num_links = static_cast<int>(truth.size()) / kValuesPerLink;
  const int index = num_links == 6 ? LinkValueIndex(name, num_links) : -1;
  if (index < 0) return std::nan("");
  const double published =
      kPaperIdentified[paper_case - 1][index / kValuesPerLink][index % kValuesPerLink];
  return published * 1e-3 - truth[index];
}

// The probes of a paper cell (nullopt for other cells).
std::optional<SummaryProbes> PaperProbes(const StoredCell& cell) {
  const int paper_case = PaperCaseOf(cell);
  if (!paper_case) return std::nullopt;
  SummaryProbes probes;
  for (int m = 0; m < 4; ++m)
    for (int a = 0; a < 3; ++a)
      probes.validation[3 * m + a] = kPaperValidation[paper_case][a][m] * 1e-3;
  for (const std::string& name : cell.parameter_names)
    probes.errors.push_back(PublishedError(cell, paper_case, name));
  probes.error_quantiles = true;
  return probes;
}

Rows PlaceCell(const CellSummary& s) {
  Rows rows;
  const int paper_case = PaperCaseOf(s.cell);
  if (!paper_case) return rows;
  const std::string label = "case " + std::to_string(paper_case);
  for (int m = 0; m < 4; ++m)
    for (int a = 0; a < 3; ++a) {
      const int k = 3 * m + a;
      rows.push_back({label, std::string("validation ") + MetricName(m), kAxes[a],
                      m % 2 == 0 ? "mm" : "mrad", Fixed(kPaperValidation[paper_case][a][m]),
                      Fixed(s.validation[k].p5 * 1e3), Fixed(s.validation[k].p50 * 1e3),
                      Fixed(s.validation[k].p95 * 1e3), Fixed(s.validation_probe_rank[k], 2)});
    }
  if (s.cell.truth_errors.size() != 6 * kValuesPerLink) return rows;
  for (std::size_t k = 0; k < s.parameters.size() && k < s.error_quantiles.size(); ++k) {
    const std::string& name = s.parameters[k].name;
    const double err = PublishedError(s.cell, paper_case, name);
    if (std::isnan(err)) continue;
    const auto& q = s.error_quantiles[k];
    rows.push_back({label, "identified error", name, UnitOf(name), Fixed(err * 1e3),
                    Fixed(q[0] * 1e3), Fixed(q[1] * 1e3), Fixed(q[2] * 1e3),
                    Fixed(s.error_probe_rank[k], 2)});
  }
  return rows;
}

// The study's cells in its canonical order (the store may also hold cells of an earlier sweep).
std::vector<StoredCell> CellsInOrder(const TrialStore& store, const Json& study) {
  std::vector<StoredCell> stored = store.Cells();
  if (!study.contains("cells")) return stored;
  std::vector<StoredCell> ordered;
  for (const auto& c : study["cells"])
    for (const auto& s : stored)
      if (s.id == c["id"]) ordered.push_back(s);
  return ordered;
}

// Cells are summarised in parallel (each thread with its own read-only connection) and kept in
// canonical order; each cell's values are released once its placement rows are made, so memory
// is a few cells' worth.
// Under a stop_when rule a cell is summarised up to its stopping point, decided from its records
// in canonical order (stopping.h): the same trials whatever computed them.
void SummarizeCells(const TrialStore& store, const std::vector<StoredCell>& cells,
                    const StopWhen& rule, long long max_trials, std::vector<CellSummary>* summaries,
                    std::vector<Rows>* placements) {
  summaries->resize(cells.size());
  placements->resize(cells.size());
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto summarize = [&] {
    try {
      TrialStore local(store.path());
      local.MapForReading();
      for (std::size_t i; (i = next.fetch_add(1)) < cells.size();) {
        CellSummary& s = (*summaries)[i];
        const std::optional<SummaryProbes> probes = PaperProbes(cells[i]);
        const SummaryProbes* p = probes ? &*probes : nullptr;
        if (rule.enabled()) {
          const CellStopping stop = EvaluateStopping({&local}, cells[i].id, rule, max_trials);
          s = SummarizeCell(local, cells[i], stop.trials_used(), p);
          s.stop = {true, stop.decided(), stop.precise(), stop.trials_used(), stop.precision()};
        } else {
          s = SummarizeCell(local, cells[i], max_trials, p);
          s.stop.decided = s.trials >= max_trials;
          s.stop.trials_used = max_trials;
        }
        (*placements)[i] = PlaceCell(s);
      }
    } catch (...) {
      std::lock_guard<std::mutex> g(failure_mutex);
      if (!failure) failure = std::current_exception();
    }
  };
  const std::size_t workers = std::max<std::size_t>(
      1, std::min<std::size_t>(cells.size(), std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  for (std::size_t w = 0; w < workers; ++w) pool.emplace_back(summarize);
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

// ---------------------------------------------------------------------------------------------
// The tables.

// The quartile-placed cells of a large study: the index at the type-7 position p (0–100) of
// `ranked` (cell indices in ascending order of their figure).
std::size_t AtPercentile(const std::vector<std::size_t>& ranked, double p) {
  const double h = static_cast<double>(ranked.size() - 1) * p / 100.0;
  return ranked[static_cast<std::size_t>(std::lround(h))];
}

// "1.23 %", or "—" when a precision cannot be stated yet.
std::string Percent(double x) { return std::isfinite(x) ? Fixed(100 * x, 2) + " %" : "—"; }

TextDocument Header(const Json& study, long long trials, const StopWhen& rule, bool complete) {
  TextDocument doc;
  doc.AddTitle("Study `" + study.value("name", std::string("?")) + "` — Monte-Carlo summary");
  if (study.contains("description") && !study["description"].get<std::string>().empty())
    doc.AddParagraph(study["description"].get<std::string>());
  std::ostringstream md;
  md << "Seed " << study.value("seed", 0ULL) << ", ";
  if (rule.enabled()) {
    md << "up to " << trials << " trials per cell in blocks of " << rule.block
       << ", each cell stopped at the first block where ";
    if (rule.relative_se > 0)
      md << "every validation mean had a relative standard error ≤ " << Percent(rule.relative_se);
    if (rule.relative_se > 0 && rule.p95_relative_halfwidth > 0) md << " and ";
    if (rule.p95_relative_halfwidth > 0)
      md << "every validation p95 had a 95 % confidence half-width ≤ "
         << Percent(rule.p95_relative_halfwidth) << " of it";
    md << " (see the cells table for the trials used)";
  } else {
    md << trials << " trials per cell";
  }
  md << ". Lengths in mm, angles in mrad; 'mean ± SE [p5, p95]' over the trials of a cell.";
  doc.AddParagraph(md.str());
  if (!complete) doc.AddNote("Partial run: some cells do not have all their trials yet.");
  return doc;
}

// Under stop_when: where each cell stopped and the precision it reached (worst metric).
std::vector<std::string> StopColumns(const CellSummary& s) {
  const CellStop& stop = s.stop;
  std::string when;
  if (!stop.decided)
    when = "not yet (running)";
  else if (stop.precise)
    when = "precision reached at " + std::to_string(stop.trials_used);
  else
    when = "maximum " + std::to_string(stop.trials_used) + " (precision not reached)";
  return {when, Percent(stop.precision.relative_se),
          Percent(stop.precision.p95_relative_halfwidth)};
}

// A cell's design criterion (E unless its settings say otherwise).
std::string DesignCriterion(const Json& settings) {
  return settings.value("/selection/criterion"_json_pointer, std::string("E"));
}

// True when the cell's design is drawn anew every trial (its pool or its selection).
bool DesignRedrawn(const Json& settings) {
  return settings.value("/selection/redraw"_json_pointer, false) ||
         settings.value("/pool/redraw"_json_pointer, false);
}

// The certified share of the best possible criterion value the cell's design reaches.
std::string DesignEfficiency(const CellSummary& s) {
  if (std::isnan(s.cell.design_efficiency)) return "—";
  return Fixed(100 * s.cell.design_efficiency, 1) + " % of the " +
         DesignCriterion(Json::parse(s.cell.settings)) + " bound";
}

// A cell's sensor and its campaign (the sensor section, shown when a study has one): the kind,
// configurations × readings, and their cost (sensor.cost_per_reading each).
std::vector<std::string> SensorColumns(const Json& settings) {
  const Json sensor = settings.value("sensor", Json::object());
  const int count = settings.value("/selection/count"_json_pointer, 0);
  const int readings = settings.value("/noise/repetitions"_json_pointer, 1);
  const double cost = sensor.value("cost_per_reading", 1.0);
  std::ostringstream campaign;
  campaign << count * static_cast<double>(readings) * cost;
  return {sensor.value("kind", std::string("ranger")),
          std::to_string(count) + " × " + std::to_string(readings), campaign.str()};
}

// The terms a cell estimates and those it holds at nominal because its configurations cannot
// separate them (identification.on_rank_deficient: fix).
std::vector<std::string> TermColumns(const CellSummary& s) {
  std::string held;
  for (const std::string& name : s.cell.fixed_for_rank) held += (held.empty() ? "" : " ") + name;
  return {std::to_string(s.cell.parameter_names.size()), held.empty() ? "—" : held};
}

Table CellsTable(const std::vector<CellSummary>& cells, const StopWhen& rule) {
  std::vector<std::string> columns = {
      "cell", "id", "trials", "ok", "failed", "sigma_min(G) of the design", "design efficiency"};
  if (rule.enabled())
    for (const char* c :
         {"stopped", "worst relative SE of a mean", "worst p95 relative half-width"})
      columns.push_back(c);
  // Shown only when a cell measures with a sensor section or holds terms, so that the tables of
  // studies without them stay as they were.
  bool sensors = false, held = false;
  for (const auto& s : cells) {
    sensors = sensors || Json::parse(s.cell.settings).contains("sensor");
    held = held || !s.cell.fixed_for_rank.empty();
  }
  if (sensors)
    for (const char* c : {"sensor", "configurations × readings", "campaign cost"})
      columns.push_back(c);
  if (sensors || held)
    for (const char* c : {"terms estimated", "held at nominal (rank)"}) columns.push_back(c);
  Table t(columns);
  for (const auto& s : cells) {
    std::string failed;
    for (const auto& [reason, n] : s.failed)
      failed += (failed.empty() ? "" : ", ") + reason + " " + std::to_string(n);
    const bool redrawn = DesignRedrawn(Json::parse(s.cell.settings));
    const std::string sigma_min =
        redrawn && s.design_sigma_min.n > 0
            ? Fixed(s.design_sigma_min.mean, 5) + " [" + Fixed(s.design_sigma_min.p5, 5) + ", " +
                  Fixed(s.design_sigma_min.p95, 5) + "] (redrawn per trial)"
            : Fixed(s.cell.design_sigma_min, 5);
    std::vector<std::string> row = {s.cell.label,
                                    s.cell.id,
                                    std::to_string(s.trials),
                                    std::to_string(s.ok),
                                    failed.empty() ? "0" : failed,
                                    sigma_min,
                                    DesignEfficiency(s)};
    if (rule.enabled())
      for (auto& c : StopColumns(s)) row.push_back(std::move(c));
    if (sensors)
      for (auto& c : SensorColumns(Json::parse(s.cell.settings))) row.push_back(std::move(c));
    if (sensors || held)
      for (auto& c : TermColumns(s)) row.push_back(std::move(c));
    t.AddRow(row);
  }
  return t;
}

// Every leaf under `value` as a dotted key below `prefix` ("selection.count"), once each.
void AddLeafKeys(const Json& value, const std::string& prefix, std::vector<std::string>* keys) {
  if (value.is_object() && !value.empty()) {
    for (const auto& [k, v] : value.items())
      AddLeafKeys(v, prefix.empty() || prefix == "." ? k : prefix + "." + k, keys);
  } else if (std::find(keys->begin(), keys->end(), prefix) == keys->end()) {
    keys->push_back(prefix);
  }
}

// The settings a study varies, as dotted keys: every leaf of every sweep axis' values (an axis
// on "." patches several settings at once) and every sensitivity input.
std::vector<std::string> VariedKeys(const Json& study) {
  std::vector<std::string> keys;
  for (const Json& axis : study.value("/sweep/axes"_json_pointer, Json::array()))
    for (const Json& v : axis.value("values", Json::array())) AddLeafKeys(v, axis["key"], &keys);
  for (const Json& input : study.value("/sensitivity/inputs"_json_pointer, Json::array()))
    AddLeafKeys(Json(), input["key"], &keys);
  return keys;
}

// A cell's setting at a dotted key, for a CSV cell: numbers as JSON writes them, text as it is,
// lists and mappings as compact JSON; empty when the cell does not have it.
std::string SettingCsvValue(const Json& settings, const std::string& key) {
  std::string pointer = "/" + key;
  std::replace(pointer.begin(), pointer.end(), '.', '/');
  const Json::json_pointer at(pointer);
  if (!settings.contains(at)) return "";
  const Json& v = settings.at(at);
  return v.is_string() ? v.get<std::string>() : v.dump();
}

// One row of cells.csv (CellsCsv).
std::vector<std::string> CellsCsvRow(const CellSummary& s, const StopWhen& rule,
                                     const std::vector<std::string>& varied) {
  long long failed = 0;
  std::string reasons;
  for (const auto& [reason, n] : s.failed) {
    failed += n;
    reasons += (reasons.empty() ? "" : "; ") + reason + " " + std::to_string(n);
  }
  const Json settings = Json::parse(s.cell.settings);
  const bool redrawn = DesignRedrawn(settings);
  const bool spread = redrawn && s.design_sigma_min.n > 0;
  std::vector<std::string> row = {
      s.cell.id,
      s.cell.label,
      std::to_string(s.trials),
      std::to_string(s.ok),
      std::to_string(failed),
      reasons,
      CsvValue(spread ? s.design_sigma_min.mean : s.cell.design_sigma_min),
      spread ? CsvValue(s.design_sigma_min.p5) : "",
      spread ? CsvValue(s.design_sigma_min.p95) : "",
      redrawn ? "1" : "0",
      CsvValue(s.cell.design_efficiency),
      DesignCriterion(settings)};
  if (rule.enabled()) {
    const CellStop& stop = s.stop;
    row.emplace_back(!stop.decided ? "running" : stop.precise ? "precision" : "maximum");
    row.push_back(std::to_string(stop.trials_used));
    row.push_back(CsvValue(stop.precision.relative_se));
    row.push_back(CsvValue(stop.precision.p95_relative_halfwidth));
  }
  for (const std::string& key : varied) row.push_back(SettingCsvValue(settings, key));
  return row;
}

// cells.csv: one row per cell, numbers as numbers (a fraction, not "99.7 % of the E bound"),
// then one column per setting the study varies, so that pandas can group by them.
Table CellsCsv(const std::vector<CellSummary>& cells, const StopWhen& rule, const Json& study) {
  std::vector<std::string> columns = {"cell_id",
                                      "cell_label",
                                      "trials",
                                      "ok",
                                      "failed",
                                      "failed_reasons",
                                      "design_sigma_min",
                                      "design_sigma_min_p5",
                                      "design_sigma_min_p95",
                                      "design_redrawn",
                                      "design_efficiency",
                                      "design_criterion"};
  if (rule.enabled())
    for (const char* c :
         {"stop_state", "trials_used", "worst_relative_se", "worst_p95_relative_halfwidth"})
      columns.emplace_back(c);
  const std::vector<std::string> varied = VariedKeys(study);
  columns.insert(columns.end(), varied.begin(), varied.end());
  Table t(columns);
  for (const auto& s : cells) t.AddRow(CellsCsvRow(s, rule, varied));
  return t;
}

// A cell's nominal rows are shown for the first cell and wherever they differ from it.
bool ShowNominal(const std::vector<CellSummary>& cells, std::size_t ci) {
  if (ci == 0) return true;
  for (int k = 0; k < 12; ++k)
    if (!SameDistribution(cells[ci].nominal[k], cells[0].nominal[k])) return true;
  return false;
}

// The first-order prediction of a validation metric's mean (identified model), NaN if none.
double PredictedMean(const CellSummary& s, int k) {
  return k < static_cast<int>(s.cell.predicted_validation.size()) ? s.cell.predicted_validation[k]
                                                                  : std::nan("");
}

// One row of validation.csv: a distribution over the trials in the table's unit (× scale).
void AddValidationCsvRow(const CellSummary& s, const char* model, const std::string& metric,
                         const char* axis, const char* unit, const Distribution& d, double scale,
                         const std::string& predicted, Table* csv) {
  csv->AddRow({s.cell.id,
               s.cell.label,
               model,
               metric,
               axis,
               unit,
               std::to_string(d.n),
               Fixed(d.mean * scale, 6),
               Fixed(d.std * scale, 6),
               Fixed(d.p5 * scale, 6),
               Fixed(d.p50 * scale, 6),
               Fixed(d.p95 * scale, 6),
               Fixed(d.max * scale, 6),
               CsvValue(d.mean_se * scale),
               CsvValue(d.std_se * scale),
               CsvValue(d.p5_ci.low * scale),
               CsvValue(d.p5_ci.high * scale),
               CsvValue(d.p50_ci.low * scale),
               CsvValue(d.p50_ci.high * scale),
               CsvValue(d.p95_ci.low * scale),
               CsvValue(d.p95_ci.high * scale),
               d.n ? Fixed(d.max_bounds_p95, 6) : "",
               predicted});
}

void AddValidationCsvRows(const CellSummary& s, bool identified, int axis, Table* csv) {
  const auto& dists = identified ? s.validation : s.nominal;
  for (int m = 0; m < 4; ++m)
    AddValidationCsvRow(s, identified ? "identified" : "nominal", MetricName(m), kAxes[axis],
                        m % 2 == 0 ? "mm" : "mrad", dists[3 * m + axis], 1e3,
                        identified ? CsvValue(PredictedMean(s, 3 * m + axis) * 1e3) : "", csv);
}

// validation.coverage's rows of validation.csv (cells that record it): metric coverage (the
// data part's radius) and coverage_total, axis "all", in % of the validation poses; the stated
// confidence, 95 %, is their mean_predicted.
void AddCoverageCsvRows(const CellSummary& s, Table* csv) {
  if (s.coverage.n == 0) return;
  AddValidationCsvRow(s, "identified", "coverage", "all", "%", s.coverage, 100, Fixed(95.0, 6),
                      csv);
  AddValidationCsvRow(s, "identified", "coverage_total", "all", "%", s.coverage_total, 100,
                      Fixed(95.0, 6), csv);
}

// validation.csv's columns; issue 14's are appended after the first ones, which scripts rely on.
std::vector<std::string> ValidationCsvColumns() {
  return {"cell_id",
          "cell_label",
          "model",
          "metric",
          "axis",
          "unit",
          "n",
          "mean",
          "std",
          "p5",
          "p50",
          "p95",
          "max",
          "mean_se",
          "std_se",
          "p5_ci_low",
          "p5_ci_high",
          "p50_ci_low",
          "p50_ci_high",
          "p95_ci_low",
          "p95_ci_high",
          "max_bounds_p95",
          "mean_predicted"};
}

// parameters.csv's and parameters.tex's tables, empty.
Table ParametersCsvTable() {
  return Table({"cell_id", "cell_label", "parameter", "unit", "bias", "bias_se", "std_empirical",
                "std_predicted", "std_ratio", "std_empirical_se", "std_ratio_se", "n",
                "std_predicted_truth", "std_ratio_truth", "std_ratio_truth_se"});
}
Table ParametersTexTable() {
  return Table({"cell", "parameter", "unit", "bias", "SE", "std", "predicted", "ratio"},
               "Parameter errors (estimate - truth), mm and mrad");
}

// Validation, laid out like the paper's table (rows model × axis).
void ValidationTable(const std::vector<CellSummary>& cells, Table* md) {
  for (std::size_t ci = 0; ci < cells.size(); ++ci) {
    const auto& s = cells[ci];
    const bool show_nominal = ShowNominal(cells, ci);
    for (int model = 0; model < 2; ++model) {
      if (model == 0 && !show_nominal) continue;
      const auto& dists = model == 0 ? s.nominal : s.validation;
      const std::string name =
          model == 0 ? "nominal" + (ci ? " (" + s.cell.label + ")" : "") : s.cell.label;
      for (int a = 0; a < 3; ++a)
        md->AddRow({name, kAxes[a], MeanRange(dists[a], 1e3), MeanRange(dists[3 + a], 1e3),
                    MeanRange(dists[6 + a], 1e3), MeanRange(dists[9 + a], 1e3)});
    }
  }
}

// validation.csv's rows: per cell, the nominal and identified model's metrics per axis, then
// its coverage.
void ValidationCsvRows(const std::vector<CellSummary>& cells, Table* csv) {
  for (const auto& s : cells) {
    for (int model = 0; model < 2; ++model)
      for (int a = 0; a < 3; ++a) AddValidationCsvRows(s, model == 1, a, csv);
    AddCoverageCsvRows(s, csv);
  }
}

// validation.coverage: how often the stated 95 % radius holds the true position error.
TextDocument CoverageSection(const std::vector<CellSummary>& cells) {
  Table t({"cell", "trials", "data part (%)", "total (%)"});
  for (const auto& s : cells) {
    if (s.coverage.n == 0) continue;
    t.AddRow(
        {s.cell.label, std::to_string(s.coverage.n),
         Fixed(s.coverage.mean * 100, 1) + " ± " + Fixed(s.coverage.mean_se * 100, 1),
         Fixed(s.coverage_total.mean * 100, 1) + " ± " + Fixed(s.coverage_total.mean_se * 100, 1)});
  }
  TextDocument doc;
  if (t.num_rows() == 0) return doc;
  doc.AddHeading("Coverage of the stated 95 % radius");
  doc.AddParagraph(
      "Share of the validation poses whose true position error lies within the 95 % radius a "
      "calibration of the cell states there (mean ± its standard error over the trials, %): "
      "the data part, from the predicted covariance at the nominal model, and the total, which "
      "adds every term the cell holds at nominal (plane and ranger terms not estimated, fixed "
      "parameters) at the identification's prior, else the robot file's tolerance, else "
      "lrcal's default (1 mm, 1 mrad, 0.5 mm for a ranger offset, 200 ppm for a scale), as "
      "identify "
      "--predict-at states them. An honest statement covers about 95 %; far below, the "
      "calibration cannot see an error the truth has (validation.csv: metric coverage, "
      "coverage_total).");
  doc.AddTable(std::move(t));
  return doc;
}

// Empirical mean of each validation metric against its first-order prediction (the planner's
// estimate), for cells that have one.
TextDocument PredictionSection(const std::vector<CellSummary>& cells) {
  Table t({"cell", "axis", kMetricTitles[0], kMetricTitles[1], kMetricTitles[2], kMetricTitles[3]});
  for (const auto& s : cells) {
    if (s.cell.predicted_validation.size() != 12 || s.ok == 0) continue;
    for (int a = 0; a < 3; ++a) {
      std::vector<std::string> row = {s.cell.label, kAxes[a]};
      for (int m = 0; m < 4; ++m) {
        const int k = 3 * m + a;
        row.push_back(Fixed(s.validation[k].mean * 1e3) + " / " + Fixed(PredictedMean(s, k) * 1e3) +
                      " (" + Fixed(s.validation[k].mean / PredictedMean(s, k), 3) + ")");
      }
      t.AddRow(row);
    }
  }
  TextDocument doc;
  if (t.num_rows() == 0) return doc;
  doc.AddHeading("Validation errors against their first-order prediction");
  doc.AddParagraph(
      "Empirical mean / "
      "predicted mean (ratio) of each validation metric of the identified model (mm, mrad). "
      "The prediction needs no trial: the covariance σ²·(GᵀWG)⁻¹ at the nominal model "
      "propagated to the validation poses through their Jacobian, each metric averaged over "
      "4000 draws of those linear errors (validation.csv: mean_predicted). A ratio near 1 says "
      "the linear model explains the cell; above 1, non-linearity, the truth's distance from "
      "the nominal model or failed fits add error.");
  doc.AddTable(std::move(t));
  return doc;
}

// Identified parameters laid out like the paper's table: link × (Δθ, Δα, Δa, Δd, Δβ), the mean
// identified Δ (truth + bias) ± the empirical std, for cells whose truth is fixed.
TextDocument PaperLayoutSection(const std::vector<CellSummary>& cells) {
  Table t({"link", "cell", "Δθ (mrad)", "Δα (mrad)", "Δa (mm)", "Δd (mm)", "Δβ (mrad)"});
  bool any = false;
  for (const auto& s : cells) {
    const std::vector<double>& truth = s.cell.truth_errors;
    if (truth.empty() || s.ok == 0) continue;
    any = true;
    for (int link = 0; link < static_cast<int>(truth.size()) / kValuesPerLink; ++link) {
      std::vector<std::string> row = {std::to_string(link + 1), s.cell.label};
      for (int v : {kTheta, kAlpha, kA, kD, kBeta}) {
        const std::string name = LinkValueFullName(kValuesPerLink * link + v);
        std::string cell = "—";
        for (const auto& p : s.parameters)
          if (p.name == name)
            cell = Fixed((truth[kValuesPerLink * link + v] + p.bias) * 1e3) + " ± " +
                   Fixed(p.std * 1e3);
        row.push_back(cell);
      }
      t.AddRow(row);
    }
  }
  TextDocument doc;
  if (!any) return doc;
  doc.AddHeading("Identified parameters (the paper's layout)");
  doc.AddParagraph(
      "Mean identified Δ ± empirical std over the trials (mrad, mm); compare with the robot "
      "file's true errors.");
  doc.AddTable(std::move(t));
  return doc;
}

// Every cell's parameter errors as rows of parameters.csv and parameters.tex.
void AddParameterRows(const std::vector<CellSummary>& cells, Table* csv, Table* tex) {
  for (const auto& s : cells)
    for (const auto& p : s.parameters) {
      const std::string unit = UnitOf(p.name);
      const double f = DisplayUnitOf(p.name).factor;
      csv->AddRow({s.cell.id, s.cell.label, p.name, unit, Fixed(p.bias * f, 6),
                   Fixed(p.bias_se * f, 6), Fixed(p.std * f, 6), Fixed(p.predicted_std * f, 6),
                   Fixed(p.ratio, 6), CsvValue(p.std_se * f), CsvValue(p.ratio_se),
                   std::to_string(s.ok), CsvValue(p.predicted_std_truth * f),
                   CsvValue(p.ratio_truth), CsvValue(p.ratio_truth_se)});
      tex->AddRow({s.cell.label, p.name, unit, Fixed(p.bias * f), Fixed(p.bias_se * f),
                   Fixed(p.std * f), Fixed(p.predicted_std * f), Fixed(p.ratio, 3)});
    }
}

// Parameter errors per cell: a Markdown table each.
TextDocument ParameterSections(const std::vector<CellSummary>& cells) {
  TextDocument doc;
  doc.AddHeading("Parameter errors (estimate − truth)");
  doc.AddParagraph(
      "Bias = mean error ± its Monte-Carlo standard "
      "error; empirical std ± its standard error; predicted std = σ·√diag(GᵀWG)⁻¹ at the "
      "nominal model (what a planner can compute) and at the true parameters (the Cramér–Rao "
      "bound of the simulated experiment; fixed truth and design only); ratio = empirical / "
      "predicted ± its standard error.");
  for (const auto& s : cells) {
    Table t({"parameter", "unit", "bias ± SE", "empirical std ± SE", "predicted std", "ratio ± SE",
             "predicted std at truth", "ratio at truth ± SE"},
            "Cell " + s.cell.label + " (" + std::to_string(s.ok) + " trials ok)");
    for (const auto& p : s.parameters) {
      const std::string unit = UnitOf(p.name);
      const double f = DisplayUnitOf(p.name).factor;
      t.AddRow({p.name, unit, Fixed(p.bias * f) + " ± " + Fixed(p.bias_se * f),
                Fixed(p.std * f) + " ± " + Fixed(p.std_se * f), Fixed(p.predicted_std * f),
                Fixed(p.ratio, 3) + " ± " + Fixed(p.ratio_se, 3), Fixed(p.predicted_std_truth * f),
                std::isnan(p.ratio_truth)
                    ? std::string("—")
                    : Fixed(p.ratio_truth, 3) + " ± " + Fixed(p.ratio_truth_se, 3)});
    }
    if (!s.cell.fixed_for_rank.empty()) {
      std::string f;
      for (const auto& x : s.cell.fixed_for_rank) f += " " + x;
      doc.AddParagraph("Fixed at nominal because of rank deficiency:" + f);
    }
    doc.AddTable(std::move(t));
  }
  return doc;
}

// The cells ShownCells chooses, each with why ("" for every cell of a small study).
std::vector<std::pair<std::size_t, std::string>> ShownCellRoles(
    const std::vector<CellSummary>& cells) {
  std::vector<std::pair<std::size_t, std::string>> out;
  if (cells.size() <= kCellsShownInFull) {
    for (std::size_t i = 0; i < cells.size(); ++i) out.emplace_back(i, "");
    return out;
  }
  std::vector<std::string> role(cells.size());
  std::vector<std::size_t> ranked;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (PaperCaseOf(cells[i].cell) != 0) role[i] = "paper";
    if (cells[i].ok > 0 && std::isfinite(cells[i].axis_mean[0].mean)) ranked.push_back(i);
  }
  // Ties in study order: the same records give the same choice.
  std::stable_sort(ranked.begin(), ranked.end(), [&](std::size_t a, std::size_t b) {
    return cells[a].axis_mean[0].mean < cells[b].axis_mean[0].mean;
  });
  if (!ranked.empty())
    for (const auto& [p, name] : {std::pair<double, const char*>{0.0, "minimum"},
                                  {25.0, "lower quartile"},
                                  {50.0, "median"},
                                  {75.0, "upper quartile"},
                                  {100.0, "maximum"}}) {
      std::string& r = role[AtPercentile(ranked, p)];
      r += (r.empty() ? "" : ", ") + std::string(name);
    }
  for (std::size_t i = 0; i < cells.size(); ++i)
    if (!role[i].empty()) out.emplace_back(i, role[i]);
  if (out.empty()) out.emplace_back(0, "first (no cell has an ok trial yet)");
  return out;
}

// Each validation metric's cell means (identified model) over the cells: min, quartiles, max.
Table CellMeansTable(const std::vector<CellSummary>& cells) {
  Table t({"metric", "axis", "cells", "min", "p25", "median", "p75", "max"});
  for (int m = 0; m < 4; ++m)
    for (int a = 0; a < 3; ++a) {
      std::vector<double> means;
      for (const auto& s : cells)
        if (s.ok > 0 && std::isfinite(s.validation[3 * m + a].mean))
          means.push_back(s.validation[3 * m + a].mean * 1e3);
      std::sort(means.begin(), means.end());
      std::vector<std::string> row = {kMetricTitles[m], kAxes[a], std::to_string(means.size())};
      for (double p : {0.0, 25.0, 50.0, 75.0, 100.0})
        row.push_back(means.empty() ? "—" : Fixed(Percentile(means, p)));
      t.AddRow(row);
    }
  return t;
}

// The shown cells with why, in the order of their error (cells without an ok trial last).
Table ShownCellsTable(const std::vector<CellSummary>& cells,
                      std::vector<std::pair<std::size_t, std::string>> roles) {
  const auto error = [&](std::size_t i) {
    return cells[i].ok > 0 ? cells[i].axis_mean[0].mean : INFINITY;
  };
  std::stable_sort(roles.begin(), roles.end(),
                   [&](const auto& a, const auto& b) { return error(a.first) < error(b.first); });
  Table t({"shown as", "cell", "id", "mean RMS pos (mm, mean of x, y, z)"});
  for (const auto& [i, role] : roles)
    t.AddRow({role, cells[i].cell.label, cells[i].cell.id,
              cells[i].ok > 0 ? Fixed(cells[i].axis_mean[0].mean * 1e3) : "—"});
  return t;
}

// A large study's aggregate: each validation metric's cell means over its cells, and which
// cells the per-cell tables show. Nothing for a study whose tables show every cell.
TextDocument AggregateSection(const std::vector<CellSummary>& cells) {
  TextDocument doc;
  const auto roles = ShownCellRoles(cells);
  if (roles.size() == cells.size()) return doc;
  doc.AddHeading("Over all " + std::to_string(cells.size()) + " cells");
  doc.AddParagraph(
      "Each cell's mean over its trials of each validation metric of the identified model, "
      "over the cells (mm, mrad; type-7 quartiles).");
  doc.AddTable(CellMeansTable(cells));
  doc.AddParagraph("The per-cell tables below show " + std::to_string(roles.size()) + " of the " +
                   std::to_string(cells.size()) +
                   " cells: the paper's, and those at the minimum, quartiles and maximum of the "
                   "mean RMS position error. Every cell is in cells.csv, validation.csv, "
                   "parameters.csv and summary.json (whose shown_cells lists these).");
  doc.AddTable(ShownCellsTable(cells, roles));
  return doc;
}

// summary.md after its header and sensitivity section: a large study's aggregate, then the
// validation errors, their prediction, the coverage, the cells, the paper's layout and the
// parameter errors of the shown cells, and the paper's numbers in lrcal's distributions.
void AppendCellSections(const std::vector<CellSummary>& cells,
                        const std::vector<CellSummary>& shown, const StopWhen& rule,
                        const Table& place, TextDocument* doc) {
  doc->Append(AggregateSection(cells));
  Table val(
      {"model", "axis", kMetricTitles[0], kMetricTitles[1], kMetricTitles[2], kMetricTitles[3]});
  ValidationTable(shown, &val);
  doc->AddHeading("Validation errors");
  doc->AddParagraph(
      "Over the validation configurations, per base axis: mean ± its "
      "standard error [p5, p95] over the trials (mm, mrad). validation.csv adds the std ± SE, "
      "95 % distribution-free confidence intervals of p5, p50 and p95 (from order statistics; "
      "empty where a cell has too few trials, e.g. below 72 for the upper end of p95), and the "
      "max over the N trials with the confidence 1 − 0.95^N that it bounds the true p95 "
      "(Wilks: at least 95 % from N = 59).");
  doc->AddTable(val);
  doc->Append(PredictionSection(shown));
  doc->Append(CoverageSection(shown));
  doc->AddHeading("Cells");
  doc->AddTable(CellsTable(shown, rule));
  doc->Append(PaperLayoutSection(shown));
  doc->Append(ParameterSections(shown));
  if (place.num_rows() == 0) return;
  doc->AddHeading("The paper's published numbers in lrcal's distributions");
  doc->AddParagraph(
      "Percentile of the "
      "published value among lrcal's trials (0 or 100: outside every trial). Identified "
      "errors are the published Δ minus the paper's own true Δ.");
  doc->AddTable(place);
}

Json NullIfNan(double x) { return std::isnan(x) ? Json() : Json(x); }

Json CellJson(const CellSummary& s) {
  Json c;
  c["id"] = s.cell.id;
  c["label"] = s.cell.label;
  c["trials"] = s.trials;
  c["ok"] = s.ok;
  c["failed"] = s.failed;
  c["design_sigma_min"] = s.cell.design_sigma_min;
  c["design_sigma_min_trials"] = DistJson(s.design_sigma_min, 1.0);
  c["design_efficiency"] = NullIfNan(s.cell.design_efficiency);
  c["fixed_for_rank"] = s.cell.fixed_for_rank;
  if (s.stop.rule) {
    const auto finite = [](double x) { return std::isfinite(x) ? Json(x) : Json(); };
    c["stop"] = {{"decided", s.stop.decided},
                 {"reason", !s.stop.decided  ? "running"
                            : s.stop.precise ? "precision"
                                             : "maximum"},
                 {"trials_used", s.stop.trials_used},
                 {"relative_se", finite(s.stop.precision.relative_se)},
                 {"p95_relative_halfwidth", finite(s.stop.precision.p95_relative_halfwidth)}};
  }
  c["settings"] = Json::parse(s.cell.settings);
  Json params = Json::array();
  for (const auto& p : s.parameters)
    params.push_back({{"name", p.name},
                      {"bias", p.bias},
                      {"bias_se", p.bias_se},
                      {"std", p.std},
                      {"std_se", NullIfNan(p.std_se)},
                      {"predicted_std", NullIfNan(p.predicted_std)},
                      {"ratio", NullIfNan(p.ratio)},
                      {"ratio_se", NullIfNan(p.ratio_se)},
                      {"predicted_std_truth", NullIfNan(p.predicted_std_truth)},
                      {"ratio_truth", NullIfNan(p.ratio_truth)},
                      {"ratio_truth_se", NullIfNan(p.ratio_truth_se)}});
  c["parameters"] = params;
  c["covariance"] = MatrixJson(s.covariance);
  c["correlation"] = MatrixJson(s.correlation);
  Json v, nm;
  for (int k = 0; k < 12; ++k) {
    v[ValidationColumnName(k)] = DistJson(s.validation[k], 1.0);
    v[ValidationColumnName(k)]["mean_predicted"] = NullIfNan(PredictedMean(s, k));
    nm[ValidationColumnName(k)] = DistJson(s.nominal[k], 1.0);
  }
  if (s.coverage.n > 0) {
    v["coverage"] = DistJson(s.coverage, 1.0);
    v["coverage_total"] = DistJson(s.coverage_total, 1.0);
  }
  c["validation"] = v;
  c["nominal_validation"] = nm;
  c["iterations"] = DistJson(s.iterations, 1.0);
  return c;
}

Json SummaryJson(const Json& study, const StudyTablesResult& result, const Json& sensitivity) {
  Json js;
  js["study"] = study;
  js["complete"] = result.complete;
  Json cells = Json::array();
  for (const auto& s : result.cells) cells.push_back(CellJson(s));
  js["cells"] = cells;
  Json shown = Json::array();
  for (std::size_t i : result.shown) shown.push_back(result.cells[i].cell.id);
  js["shown_cells"] = shown;
  if (!sensitivity.is_null()) js["sensitivity"] = sensitivity;
  return js;
}

// ---------------------------------------------------------------------------------------------
// Sensitivity (study/sensitivity.h): the quantity of interest at each plan point is the cell's
// mean over its trials of the identified model's metric, averaged over the x, y and z axes (mm or
// mrad); its Monte-Carlo noise (the cell means' standard errors) is stated as a share of the
// variance over the plan.

struct SensitivityOutput {
  Json json;              // null without a sensitivity section
  TextDocument document;  // the summary.md section
  Table plan{{}};         // sensitivity_plan.csv: inputs and output per plan point
  Table csv{{"input", "min", "max", "method", "first", "first_low", "first_high", "total",
             "total_low", "total_high", "mu", "mu_star", "sigma"}};
};

// Per cell id: the quantity of interest (the cell mean; NaN for a cell without ok trials), its
// squared SE, and the variance of a single trial's figure about it (mm² or mrad²).
struct CellQuantity {
  double mean = NAN, se2 = 0, trial_variance = NAN;
};
std::map<std::string, CellQuantity> CellQuantities(const std::vector<CellSummary>& cells,
                                                   int metric) {
  std::map<std::string, CellQuantity> q;
  for (const CellSummary& s : cells) {
    CellQuantity c;
    c.mean = 0;
    for (int a = 0; a < 3; ++a) {
      const Distribution& d = s.validation[3 * metric + a];
      c.mean += (d.n > 0 ? d.mean : NAN) * 1e3 / 3;
    }
    // The cell mean's Monte-Carlo variance from the per-trial mean over x, y, z: the three axes
    // of one trial are correlated (about 0.67 for rms_pos), so their squared standard errors do
    // not add.
    const Distribution& t = s.axis_mean[metric];
    c.se2 = t.n > 1 ? t.mean_se * t.mean_se * 1e6 : 0;
    c.trial_variance = t.n > 1 ? t.std * t.std * 1e6 : NAN;
    q[s.cell.id] = c;
  }
  return q;
}

// An input's law in words, and its CSV min and max (empty for a normal input).
bool IsNormalInput(const Json& input) { return input.contains("mean"); }
std::string InputRange(const Json& input) {
  if (IsNormalInput(input))
    return "normal, mean " + Fixed(input["mean"].get<double>(), 4) + ", std " +
           Fixed(input["std"].get<double>(), 4);
  return Fixed(input["min"].get<double>(), 4) + " to " + Fixed(input["max"].get<double>(), 4);
}
std::string InputBound(const Json& input, const char* key) {
  return IsNormalInput(input) ? "" : CsvValue(input[key].get<double>());
}

// Sobol indices with bootstrap intervals: the table, the CSV rows and the JSON inputs. `scale`
// turns indices of the cell means into indices of a single trial's figure (1 for the cell
// means; see SensitivityAnalysis).
void SobolSection(const Json& spec, const Eigen::VectorXd& values, std::uint64_t seed, double scale,
                  SensitivityOutput* out) {
  const int d = static_cast<int>(spec["inputs"].size()), bootstrap = spec["bootstrap"];
  const SaltelliPlan plan{spec["samples"].get<int>(), d, {}};
  SobolIndices s = EstimateSobolIndices(plan, values, bootstrap, 0.95, seed);
  for (auto* list : {&s.first, &s.total})
    for (IntervalEstimate& e : *list) {
      e.estimate *= scale;
      e.low *= scale;
      e.high *= scale;
    }
  Table table({"input", "range", "first-order S [95 % CI]",
               scale == 1 ? "total T [95 % CI]" : "total T, at least [95 % CI]"});
  const auto ci = [](const IntervalEstimate& e) {
    return Fixed(e.estimate, 3) + " [" + Fixed(e.low, 3) + ", " + Fixed(e.high, 3) + "]";
  };
  Json inputs = Json::array();
  for (int i = 0; i < d; ++i) {
    const Json& in = spec["inputs"][i];
    const std::string key = in["key"];
    table.AddRow({key, InputRange(in), ci(s.first[i]), ci(s.total[i])});
    out->csv.AddRow({key, InputBound(in, "min"), InputBound(in, "max"), "sobol",
                     CsvValue(s.first[i].estimate), CsvValue(s.first[i].low),
                     CsvValue(s.first[i].high), CsvValue(s.total[i].estimate),
                     CsvValue(s.total[i].low), CsvValue(s.total[i].high), "", "", ""});
    inputs.push_back({{"key", key},
                      {"first", {s.first[i].estimate, s.first[i].low, s.first[i].high}},
                      {"total", {s.total[i].estimate, s.total[i].low, s.total[i].high}}});
  }
  out->json["inputs"] = inputs;
  out->document.AddParagraph(
      "Saltelli's plan, N = " + std::to_string(plan.base_samples) + " base samples, " +
      std::to_string(d) +
      " inputs; first-order by Saltelli et al. (2010), total by Jansen (1999), 95 % "
      "percentile-bootstrap intervals (" +
      std::to_string(bootstrap) + " resamples).");
  out->document.AddTable(std::move(table));
}

// Morris elementary effects: the table, the CSV rows and the JSON inputs.
void MorrisSection(const Json& spec, const Eigen::VectorXd& values, std::uint64_t seed,
                   const std::string& unit, SensitivityOutput* out) {
  const int d = static_cast<int>(spec["inputs"].size()), levels = spec["levels"];
  const MorrisPlan plan = MakeMorrisPlan(spec["samples"].get<int>(), d, levels, seed);
  const MorrisEffects e = EstimateMorrisEffects(plan, values);
  Table table(
      {"input", "range", "mu* (" + unit + ")", "mu (" + unit + ")", "sigma (" + unit + ")"});
  Json inputs = Json::array();
  for (int i = 0; i < d; ++i) {
    const Json& in = spec["inputs"][i];
    const std::string key = in["key"];
    table.AddRow(
        {key, InputRange(in), Fixed(e.mu_star[i], 4), Fixed(e.mu[i], 4), Fixed(e.sigma[i], 4)});
    out->csv.AddRow({key, InputBound(in, "min"), InputBound(in, "max"), "morris", "", "", "", "",
                     "", "", CsvValue(e.mu[i]), CsvValue(e.mu_star[i]), CsvValue(e.sigma[i])});
    inputs.push_back(
        {{"key", key}, {"mu", e.mu[i]}, {"mu_star", e.mu_star[i]}, {"sigma", e.sigma[i]}});
  }
  out->json["inputs"] = inputs;
  out->document.AddParagraph(
      "Morris' plan, " + std::to_string(plan.trajectories) + " trajectories on a " +
      std::to_string(levels) +
      "-level grid; elementary effects are the change of the quantity of interest across "
      "each input's whole range (Δ of the unit cube scaled to 1).");
  out->document.AddTable(std::move(table));
}

// quantity: trial. A single calibration's figure Y = f(x) + ε, the noise ε one more input
// (Marrel et al. 2012, stochastic simulators): Var Y = Var f + E[Var(Y|x)]. The noise's total
// index is E[Var(Y|x)] / Var Y (exact); an input's first-order index is V_i / Var Y, the cell
// means' index times Var(cell means) / Var Y; its total index is at least the cell means' one
// times the same ratio (Jensen), so it is reported as a lower bound. Returns the ratio and adds
// the JSON keys and the markdown paragraph.
double TrialQuantity(const Eigen::VectorXd& within, double variance, double noise,
                     const std::string& unit, SensitivityOutput* out) {
  const double var_f = std::max(variance - noise, 0.0), mean_within = within.mean();
  const double var_y = var_f + mean_within;
  const double share = var_y > 0 ? mean_within / var_y : NAN;
  out->json["quantity"] = "trial";
  out->json["trial_variance"] = var_y;
  out->json["noise_total"] = share;
  std::ostringstream md;
  md << "Quantity of interest for the indices: a single calibration's figure (one trial), the "
        "trial's randomness (reading noise, and whatever else the study draws per trial) one "
        "more input (Marrel et al. 2012): its variance "
     << Fixed(var_y, 6) << " " << unit << "² = the cell means' " << Fixed(var_f, 6)
     << " (Monte-Carlo noise removed) + the mean within-cell variance " << Fixed(mean_within, 6)
     << ". The noise's total index is " << Fixed(share, 3)
     << "; the inputs' first-order indices are exact, their total indices lower bounds (the "
        "noise's interactions with an input cannot be told from its own share; up to the cell "
        "means' Monte-Carlo noise).";
  out->document.AddParagraph(md.str());
  return var_y > 0 ? variance / var_y : NAN;
}

// sensitivity_plan.csv: per plan point its cell, the inputs' values and the quantity of interest
// (the cell mean, averaged over x, y and z) with its Monte-Carlo standard error: what SALib or
// pandas would take.
Table SensitivityPlanTable(const Json& spec, const std::vector<CellSummary>& cells,
                           const std::map<std::string, CellQuantity>& quantities,
                           const std::string& metric, const std::string& unit) {
  std::vector<std::string> columns = {"point", "cell_id"};
  for (const Json& input : spec["inputs"]) columns.push_back(input["key"]);
  for (const char* c : {"_mean_", "_se_"}) columns.push_back(metric + c + unit);
  columns.emplace_back("ok");
  Table t(columns);
  std::map<std::string, const CellSummary*> by_id;
  for (const CellSummary& s : cells) by_id[s.cell.id] = &s;
  const Json& plan_cells = spec["plan_cells"];
  for (std::size_t p = 0; p < plan_cells.size(); ++p) {
    const std::string id = plan_cells[p];
    std::vector<std::string> row = {std::to_string(p), id};
    const auto cell = by_id.find(id);
    const Json settings = cell == by_id.end() ? Json() : Json::parse(cell->second->cell.settings);
    for (const Json& input : spec["inputs"])
      row.push_back(settings.is_null() ? "" : SettingCsvValue(settings, input["key"]));
    const auto q = quantities.find(id);
    const bool known = q != quantities.end();
    row.push_back(known ? CsvValue(q->second.mean) : "");
    row.push_back(known && q->second.se2 > 0 ? CsvValue(std::sqrt(q->second.se2)) : "");
    row.push_back(cell == by_id.end() ? "0" : std::to_string(cell->second->ok));
    t.AddRow(row);
  }
  return t;
}

SensitivityOutput SensitivityAnalysis(const Json& study, const std::vector<CellSummary>& cells) {
  SensitivityOutput out;
  if (!study.contains("sensitivity")) return out;
  const Json& spec = study["sensitivity"];
  const std::string method = spec["method"], metric_name = spec["metric"];
  const bool trial = spec.value("quantity", std::string("cell_mean")) == "trial";
  const int metric = static_cast<int>(
      ParseName(kValidationMetricNames, metric_name, "sensitivity.metric", "metric"));
  const std::uint64_t seed = study.value("seed", std::uint64_t{0});
  const auto quantities = CellQuantities(cells, metric);
  const Json& plan_cells = spec["plan_cells"];
  const auto points = static_cast<Eigen::Index>(plan_cells.size());
  Eigen::VectorXd values(points), within(points);
  double noise = 0;
  for (Eigen::Index p = 0; p < points; ++p) {
    const auto it = quantities.find(plan_cells[p].get<std::string>());
    const CellQuantity q = it == quantities.end() ? CellQuantity{} : it->second;
    values[p] = q.mean;
    within[p] = q.trial_variance;
    noise += q.se2 / static_cast<double>(points);
  }
  const std::string unit = metric % 2 == 0 ? "mm" : "mrad";
  out.plan = SensitivityPlanTable(spec, cells, quantities, metric_name, unit);
  out.json = {{"method", method}, {"metric", metric_name}, {"unit", unit}};
  out.document.AddHeading(std::string("Sensitivity (") +
                          (method == "sobol" ? "Sobol indices" : "Morris effects") + ")");
  std::ostringstream md;
  md << (trial ? "Cell means" : "Quantity of interest")
     << ": each cell's mean over its trials of the identified model's " << metric_name << " ("
     << unit << "), averaged over x, y and z, at " << values.size() << " plan points ("
     << cells.size() << " cells).";
  out.json["available"] = values.allFinite() && (!trial || within.allFinite());
  if (!out.json["available"].get<bool>()) {
    out.document.AddParagraph(md.str() +
                              (trial ? " Some cells have fewer than two successful trials"
                                     : " Some cells have no successful trial") +
                              ": no indices.");
    return out;
  }
  const double variance = (values.array() - values.mean()).square().sum() /
                          static_cast<double>(std::max<Eigen::Index>(1, values.size() - 1));
  out.json["variance"] = variance;
  out.json["noise_variance"] = noise;
  md << " Variance over the plan " << Fixed(variance, 6) << " " << unit << "²; the cell means' "
     << "Monte-Carlo noise is " << Percent(variance > 0 ? noise / variance : NAN)
     << " of it (it adds to every total index and lowers the first-order ones).";
  out.document.AddParagraph(md.str());
  const double scale = trial ? TrialQuantity(within, variance, noise, unit, &out) : 1.0;
  if (method == "sobol")
    SobolSection(spec, values, seed, scale, &out);
  else
    MorrisSection(spec, values, seed, unit, &out);
  if (trial)
    out.csv.AddRow({"noise (one trial)", "", "", "sobol", "", "", "",
                    CsvValue(out.json["noise_total"].get<double>()), "", "", "", "", ""});
  return out;
}

}  // namespace

std::vector<std::size_t> ShownCells(const std::vector<CellSummary>& cells) {
  std::vector<std::size_t> out;
  for (const auto& [i, role] : ShownCellRoles(cells)) out.push_back(i);
  return out;
}

StudyTablesResult WriteStudyTables(const TrialStore& store, const Json& study,
                                   const std::string& run_dir) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(run_dir) / "tables";
  fs::create_directories(dir);
  StudyTablesResult result;
  const long long trials = study.value("trials", 0LL);
  const StopWhen rule =
      StopWhen::FromJson(study.value("stop_when", Json()), "manifest study.stop_when");
  std::vector<Rows> placements;
  SummarizeCells(store, CellsInOrder(store, study), rule, trials, &result.cells, &placements);
  for (const auto& s : result.cells)
    if (!s.stop.decided || s.trials < s.stop.trials_used) result.complete = false;
  Table place({"case", "quantity", "axis/parameter", "unit", "paper", "lrcal p5", "lrcal p50",
               "lrcal p95", "percentile of paper"});
  for (const auto& rows : placements)
    for (const auto& row : rows) place.AddRow(row);

  result.shown = ShownCells(result.cells);
  std::vector<CellSummary> shown;  // what the summary's per-cell tables show
  for (std::size_t i : result.shown) shown.push_back(result.cells[i]);

  Table val(
      {"model", "axis", kMetricTitles[0], kMetricTitles[1], kMetricTitles[2], kMetricTitles[3]});
  Table val_csv(ValidationCsvColumns());
  ValidationTable(result.cells, &val);
  ValidationCsvRows(result.cells, &val_csv);
  Table par_csv = ParametersCsvTable(), par_tex = ParametersTexTable();
  AddParameterRows(result.cells, &par_csv, &par_tex);

  // The headline first: the sensitivity indices of a sensitivity plan, an aggregate over the
  // cells of a large study, then the validation errors.
  TextDocument& doc = result.document;
  doc.Append(Header(study, trials, rule, result.complete));
  const SensitivityOutput sensitivity = SensitivityAnalysis(study, result.cells);
  doc.Append(sensitivity.document);
  AppendCellSections(result.cells, shown, rule, place, &doc);
  const bool any_paper = place.num_rows() > 0;

  // Each file is written whole or not at all (a temporary name, checked and renamed).
  const auto write = [&](const char* name, const std::string& text) {
    WriteFileAtomically((dir / name).string(), text);
  };
  write("summary.md", doc.ToMarkdown());
  write("cells.csv", CellsCsv(result.cells, rule, study).ToCsv());
  write("validation.csv", val_csv.ToCsv());
  write("parameters.csv", par_csv.ToCsv());
  if (any_paper) write("paper_placement.csv", place.ToCsv());
  if (!sensitivity.json.is_null()) {
    write("sensitivity.csv", sensitivity.csv.ToCsv());
    write("sensitivity_plan.csv", sensitivity.plan.ToCsv());
  }
  write("summary.json", SummaryJson(study, result, sensitivity.json).dump(1) + "\n");
  write("validation.tex", val.ToLatex());
  write("parameters.tex", par_tex.ToLatex());
  return result;
}

}  // namespace lrcal
