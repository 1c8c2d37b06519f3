#include "lrcal/report/study_tables.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <atomic>
#include <mutex>
#include <sstream>
#include <thread>

#include "lrcal/core/error.h"
#include "lrcal/paper/paper_case.h"
#include "lrcal/measurement/parameter_set.h"
#include "lrcal/core/text_table.h"

namespace lrcal {

namespace {

const char* kMetricNames[4] = {"rms_pos", "rms_ori", "max_pos", "max_ori"};
const char* kMetricTitles[4] = {"RMS pos (mm)", "RMS ori (mrad)", "max pos (mm)", "max ori (mrad)"};
const char* kAxes[3] = {"x", "y", "z"};

std::string MeanRange(const Distribution& d, double scale) {
  if (d.n == 0) return "—";
  return Fixed(d.mean * scale) + " [" + Fixed(d.p5 * scale) + ", " + Fixed(d.p95 * scale) + "]";
}

void WriteFile(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write " + path.string());
  out << text;
}

Json DistJson(const Distribution& d, double scale) {
  auto v = [&](double x) { return std::isnan(x) ? Json() : Json(x * scale); };
  return {{"n", d.n}, {"mean", v(d.mean)}, {"std", v(d.std)}, {"p5", v(d.p5)},
          {"p50", v(d.p50)}, {"p95", v(d.p95)}, {"max", v(d.max)}};
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

}  // namespace

StudyTablesResult WriteStudyTables(const TrialStore& store, const Json& study,
                                   const std::string& run_dir) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(run_dir) / "tables";
  fs::create_directories(dir);
  StudyTablesResult result;
  const long long trials = study.value("trials", 0LL);
  // The paper's published numbers in our distributions.
  Table place({"case", "quantity", "axis/parameter", "unit", "paper", "lrcal p5", "lrcal p50",
               "lrcal p95", "percentile of paper"});
  bool any_paper = false;
  // Placement needs a cell's sorted values; it runs as each cell is summarised, after which the
  // values are released (memory: one cell's worth).
  // Returns the cell's placement rows (none unless it is a paper cell).
  auto place_cell = [](const CellSummary& s) {
    std::vector<std::vector<std::string>> rows;
    const Json settings = Json::parse(s.cell.settings);
    const int pc = settings.value("paper_case", 0);
    if (pc < 1 || pc > 2) return rows;
    const std::string label = "case " + std::to_string(pc);
    for (int m = 0; m < 4; ++m) {
      for (int a = 0; a < 3; ++a) {
        const int k = 3 * m + a;
        const double paper = kPaperValidation[pc][a][m];
        const auto& sorted = s.validation_values[k];
        rows.push_back({label, std::string("validation ") + kMetricNames[m], kAxes[a],
                      m % 2 == 0 ? "mm" : "mrad", Fixed(paper), Fixed(s.validation[k].p5 * 1e3),
                      Fixed(s.validation[k].p50 * 1e3), Fixed(s.validation[k].p95 * 1e3),
                      Fixed(PercentileRank(sorted, paper * 1e-3), 2)});
      }
    }
    // Identified parameters: published error = published Δ − the robot file's true Δ.
    // The truth recorded with the cell (the robot file's errors × truth.scale): no robot file is
    // read again after the run.
    const std::vector<double>& truth = s.cell.truth_errors;
    const int num_links = static_cast<int>(truth.size()) / kValuesPerLink;
    if (num_links == 6) {
      {
        for (std::size_t k = 0; k < s.parameters.size(); ++k) {
          const int index = LinkValueIndex(s.parameters[k].name, num_links);
          if (index < 0) continue;
          const double published = kPaperIdentified[pc - 1][index / kValuesPerLink][index % kValuesPerLink];
          if (std::isnan(published)) continue;
          const double err = published * 1e-3 - truth[index];
          std::vector<double> values = s.error_values[k];
          rows.push_back({label, "identified error", s.parameters[k].name,
                        IsAngularName(s.parameters[k].name) ? "mrad" : "mm", Fixed(err * 1e3),
                        Fixed(Quantile(&values, 5) * 1e3), Fixed(Quantile(&values, 50) * 1e3),
                        Fixed(Quantile(&values, 95) * 1e3), Fixed(PercentileRank(values, err), 2)});
        }
      }
    }
    return rows;
  };
  // The study's cells in its canonical order (the store may also hold cells of an earlier sweep).
  std::vector<StoredCell> stored = store.Cells();
  std::vector<StoredCell> cells_in_order;
  if (study.contains("cells")) {
    for (const auto& c : study["cells"])
      for (const auto& s : stored)
        if (s.id == c["id"]) cells_in_order.push_back(s);
  } else {
    cells_in_order = stored;
  }
  // Cells are summarised in parallel (each thread with its own read-only connection) and kept in
  // canonical order; each cell's values are released once its placement rows are made, so
  // memory is a few cells' worth.
  const std::size_t num_cells = cells_in_order.size();
  result.cells.resize(num_cells);
  std::vector<std::vector<std::vector<std::string>>> place_rows(num_cells);
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto summarize = [&] {
    try {
      TrialStore local(store.path());
      for (std::size_t i; (i = next.fetch_add(1)) < num_cells;) {
        CellSummary& s = result.cells[i];
        s = SummarizeCell(local, cells_in_order[i]);
        place_rows[i] = place_cell(s);
        for (auto& v : s.validation_values) std::vector<double>().swap(v);
        std::vector<std::vector<double>>().swap(s.error_values);
      }
    } catch (...) {
      std::lock_guard<std::mutex> g(failure_mutex);
      if (!failure) failure = std::current_exception();
    }
  };
  const std::size_t workers =
      std::max<std::size_t>(1, std::min<std::size_t>(num_cells, std::thread::hardware_concurrency()));
  std::vector<std::thread> pool;
  for (std::size_t w = 0; w < workers; ++w) pool.emplace_back(summarize);
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
  for (const auto& s : result.cells)
    if (s.trials < trials) result.complete = false;
  for (const auto& rows : place_rows) {
    for (const auto& row : rows) place.AddRow(row);
    any_paper |= !rows.empty();
  }

  std::ostringstream md;
  md << "# Study `" << study.value("name", std::string("?")) << "` — Monte-Carlo summary\n\n";
  if (study.contains("description") && !study["description"].get<std::string>().empty())
    md << study["description"].get<std::string>() << "\n\n";
  md << "Seed " << study.value("seed", 0ULL) << ", " << trials
     << " trials per cell. Lengths in mm, angles in mrad; 'mean [p5, p95]' over the trials of a "
        "cell.\n";
  if (!result.complete) md << "\n**Partial run: some cells do not have all their trials yet.**\n";

  // Cells.
  Table cells({"cell", "id", "trials", "ok", "failed", "sigma_min(G) of the design"});
  for (const auto& s : result.cells) {
    std::string failed;
    for (const auto& [reason, n] : s.failed) failed += (failed.empty() ? "" : ", ") + reason + " " + std::to_string(n);
    cells.AddRow({s.cell.label, s.cell.id, std::to_string(s.trials), std::to_string(s.ok),
                  failed.empty() ? "0" : failed, Fixed(s.cell.design_sigma_min, 5)});
  }
  md << "\n## Cells\n\n" << cells.ToMarkdown();

  // Validation, laid out like the paper's table: rows model × axis.
  Table val({"model", "axis", kMetricTitles[0], kMetricTitles[1], kMetricTitles[2], kMetricTitles[3]});
  Table val_csv({"cell_id", "cell_label", "model", "metric", "axis", "unit", "n", "mean", "std",
                 "p5", "p50", "p95", "max"});
  const Distribution* first_nominal = result.cells.empty() ? nullptr : result.cells[0].nominal.data();
  for (std::size_t ci = 0; ci < result.cells.size(); ++ci) {
    const auto& s = result.cells[ci];
    bool show_nominal = ci == 0;
    for (int k = 0; k < 12 && !show_nominal; ++k)
      show_nominal = !SameDistribution(s.nominal[k], first_nominal[k]);
    for (int model = 0; model < 2; ++model) {
      const auto& dists = model == 0 ? s.nominal : s.validation;
      const std::string name = model == 0 ? "nominal" + (ci ? " (" + s.cell.label + ")" : "")
                                          : s.cell.label;
      for (int a = 0; a < 3; ++a) {
        if (model == 1 || show_nominal)
          val.AddRow({name, kAxes[a], MeanRange(dists[a], 1e3), MeanRange(dists[3 + a], 1e3),
                      MeanRange(dists[6 + a], 1e3), MeanRange(dists[9 + a], 1e3)});
        for (int m = 0; m < 4; ++m) {
          const Distribution& d = dists[3 * m + a];
          val_csv.AddRow({s.cell.id, s.cell.label, model == 0 ? "nominal" : "identified",
                          kMetricNames[m], kAxes[a], m % 2 == 0 ? "mm" : "mrad",
                          std::to_string(d.n), Fixed(d.mean * 1e3, 6), Fixed(d.std * 1e3, 6),
                          Fixed(d.p5 * 1e3, 6), Fixed(d.p50 * 1e3, 6), Fixed(d.p95 * 1e3, 6),
                          Fixed(d.max * 1e3, 6)});
        }
      }
    }
  }
  md << "\n## Validation errors\n\nOver the validation configurations, per base axis: mean "
        "[p5, p95] over the trials (mm, mrad).\n\n"
     << val.ToMarkdown();

  // Identified parameters laid out like the paper's table: link × (Δθ, Δα, Δa, Δd, Δβ), the
  // mean identified Δ (truth + bias) ± the empirical std, for cells whose truth is fixed.
  {
    Table paper_layout({"link", "cell", "Δθ (mrad)", "Δα (mrad)", "Δa (mm)", "Δd (mm)", "Δβ (mrad)"});
    bool any = false;
    for (const auto& s : result.cells) {
      const Json settings = Json::parse(s.cell.settings);
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
        paper_layout.AddRow(row);
      }
    }
    if (any)
      md << "\n## Identified parameters (the paper's layout)\n\nMean identified Δ ± empirical "
            "std over the trials (mrad, mm); compare with the robot file's true errors.\n\n"
         << paper_layout.ToMarkdown();
  }

  // Parameters per cell.
  Table par_csv({"cell_id", "cell_label", "parameter", "unit", "bias", "bias_se", "std_empirical",
                 "std_predicted", "std_ratio"});
  Table par_tex({"cell", "parameter", "unit", "bias", "SE", "std", "predicted", "ratio"},
                "Parameter errors (estimate - truth), mm and mrad");
  md << "\n## Parameter errors (estimate − truth)\n\nBias = mean error ± its Monte-Carlo standard "
        "error; predicted std = σ·√diag(GᵀWG)⁻¹ at the nominal model; ratio = empirical / "
        "predicted.\n";
  for (const auto& s : result.cells) {
    Table t({"parameter", "unit", "bias ± SE", "empirical std", "predicted std", "ratio"},
            "Cell " + s.cell.label + " (" + std::to_string(s.ok) + " trials ok)");
    for (const auto& p : s.parameters) {
      const std::string unit = IsAngularName(p.name) ? "mrad" : "mm";
      t.AddRow({p.name, unit, Fixed(p.bias * 1e3) + " ± " + Fixed(p.bias_se * 1e3),
                Fixed(p.std * 1e3), Fixed(p.predicted_std * 1e3), Fixed(p.ratio, 3)});
      par_csv.AddRow({s.cell.id, s.cell.label, p.name, unit, Fixed(p.bias * 1e3, 6),
                      Fixed(p.bias_se * 1e3, 6), Fixed(p.std * 1e3, 6),
                      Fixed(p.predicted_std * 1e3, 6), Fixed(p.ratio, 6)});
      par_tex.AddRow({s.cell.label, p.name, unit, Fixed(p.bias * 1e3), Fixed(p.bias_se * 1e3),
                      Fixed(p.std * 1e3), Fixed(p.predicted_std * 1e3), Fixed(p.ratio, 3)});
    }
    if (!s.cell.fixed_for_rank.empty()) {
      std::string f;
      for (const auto& x : s.cell.fixed_for_rank) f += " " + x;
      md << "\nFixed at nominal because of rank deficiency:" << f << "\n";
    }
    md << "\n" << t.ToMarkdown();
  }

  if (any_paper) {
    md << "\n## The paper's published numbers in lrcal's distributions\n\nPercentile of the "
          "published value among lrcal's trials (0 or 100: outside every trial). Identified "
          "errors are the published Δ minus the paper's own true Δ.\n\n"
       << place.ToMarkdown();
  }

  // summary.json
  Json js;
  js["study"] = study;
  js["complete"] = result.complete;
  Json jc = Json::array();
  for (const auto& s : result.cells) {
    Json c;
    c["id"] = s.cell.id;
    c["label"] = s.cell.label;
    c["trials"] = s.trials;
    c["ok"] = s.ok;
    c["failed"] = s.failed;
    c["design_sigma_min"] = s.cell.design_sigma_min;
    c["fixed_for_rank"] = s.cell.fixed_for_rank;
    c["settings"] = Json::parse(s.cell.settings);
    Json params = Json::array();
    for (const auto& p : s.parameters)
      params.push_back({{"name", p.name}, {"bias", p.bias}, {"bias_se", p.bias_se}, {"std", p.std},
                        {"predicted_std", std::isnan(p.predicted_std) ? Json() : Json(p.predicted_std)},
                        {"ratio", std::isnan(p.ratio) ? Json() : Json(p.ratio)}});
    c["parameters"] = params;
    c["covariance"] = MatrixJson(s.covariance);
    c["correlation"] = MatrixJson(s.correlation);
    Json v, nm;
    for (int k = 0; k < 12; ++k) {
      v[TrialStore::kMetricColumns[k]] = DistJson(s.validation[k], 1.0);
      nm[TrialStore::kMetricColumns[k]] = DistJson(s.nominal[k], 1.0);
    }
    c["validation"] = v;
    c["nominal_validation"] = nm;
    c["iterations"] = DistJson(s.iterations, 1.0);
    jc.push_back(c);
  }
  js["cells"] = jc;

  WriteFile(dir / "summary.md", md.str());
  WriteFile(dir / "cells.csv", cells.ToCsv());
  WriteFile(dir / "validation.csv", val_csv.ToCsv());
  WriteFile(dir / "parameters.csv", par_csv.ToCsv());
  if (any_paper) WriteFile(dir / "paper_placement.csv", place.ToCsv());
  WriteFile(dir / "summary.json", js.dump(1) + "\n");
  WriteFile(dir / "validation.tex", val.ToLatex());
  WriteFile(dir / "parameters.tex", par_tex.ToLatex());
  result.markdown = md.str();
  return result;
}

}  // namespace lrcal
