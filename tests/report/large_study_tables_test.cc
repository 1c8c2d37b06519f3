// The summary of a large study (more than kCellsShownInFull cells): the sensitivity indices and an
// aggregate over every cell first, per-cell tables for a chosen few (ShownCells), every cell in
// the CSV and JSON files.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "lrcal/io/csv.h"
#include "lrcal/report/study_tables.h"
#include "test_util.h"

namespace lrcal {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// A cell summary whose mean validation RMS position error (mean over the axes) is `error`.
CellSummary Summary(const std::string& id, double error, long long ok = 10) {
  CellSummary s;
  s.cell.id = id;
  s.cell.label = id;
  s.cell.settings = "{}";
  s.ok = ok;
  s.axis_mean[0].mean = error;
  return s;
}

TEST(ShownCells, EveryCellOfASmallStudy) {
  std::vector<CellSummary> cells;
  for (std::size_t i = 0; i < kCellsShownInFull; ++i)
    cells.push_back(Summary("c" + std::to_string(i), 1.0 / (1.0 + static_cast<double>(i))));
  const std::vector<std::size_t> shown = ShownCells(cells);
  ASSERT_EQ(shown.size(), cells.size());
  for (std::size_t i = 0; i < shown.size(); ++i) EXPECT_EQ(shown[i], i);
}

// Of 29 cells with errors 0 … 28 (shuffled in study order), a cell without an ok trial and a paper
// cell: the failed cell is never ranked, the paper's is always shown, and the result is in study
// order.
TEST(ShownCells, ThePaperCellsAndTheQuartilesOfALargeStudy) {
  std::vector<CellSummary> cells;
  for (int i = 0; i < 29; ++i) cells.push_back(Summary("c" + std::to_string(i), (i * 11) % 29));
  cells.push_back(Summary("failed", 0.0, 0));
  cells.push_back(Summary("paper", 100.0));
  cells.back().cell.settings = R"({"paper_case": 2})";
  std::vector<std::size_t> shown = ShownCells(cells);
  // Ranked: the 29 cells and the paper cell (30 values); quartile positions round(29·p/100):
  // 0, 7, 15, 22, 29 → errors 0, 7, 15, 22 and the paper cell's 100. Error e sits at study
  // index 8·e mod 29 (11·8 ≡ 1 mod 29).
  std::vector<std::size_t> want;
  for (int error : {0, 7, 15, 22}) want.push_back(static_cast<std::size_t>((8 * error) % 29));
  want.push_back(30);
  std::sort(want.begin(), want.end());
  EXPECT_EQ(shown, want);
  EXPECT_EQ(std::count(shown.begin(), shown.end(), 29u), 0);  // the failed cell
}

TEST(ShownCells, TheFirstCellWhenNoneHasAnOkTrialYet) {
  std::vector<CellSummary> cells;
  for (std::size_t i = 0; i <= kCellsShownInFull; ++i)
    cells.push_back(Summary("c" + std::to_string(i), 1.0, 0));
  EXPECT_THAT(ShownCells(cells), ElementsAre(0u));
}

// A 32-cell Sobol plan of 10 trials a cell, run through the program.
class LargeStudy : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = testing::TempDir("large_study_tables");
    std::ofstream(dir_ + "/s.yaml")
        << "name: large\nseed: 3\ntrials: 10\npool: {size: 60}\nselection: {count: 40}\n"
           "validation: {size: 10}\nsensitivity:\n  samples: 8\n  bootstrap: 100\n  inputs:\n"
           "    - {key: noise.sigma_mm, min: 0.05, max: 0.4}\n"
           "    - {key: noise.form_sigma_mm, min: 0, max: 0.1}\n";
    ASSERT_TRUE(testing::RunStudyFile(dir_ + "/s.yaml", dir_ + "/run", 2).complete);
  }
  static std::string Table(const std::string& name) {
    return testing::ReadFile(dir_ + "/run/tables/" + name);
  }
  static std::string dir_;
};
std::string LargeStudy::dir_;

TEST_F(LargeStudy, TheSummaryLeadsWithTheIndicesAndTheAggregate) {
  const std::string md = Table("summary.md");
  const auto at = [&](const std::string& heading) { return md.find(heading); };
  ASSERT_NE(at("## Sensitivity (Sobol"), std::string::npos);
  ASSERT_NE(at("## Over all 32 cells"), std::string::npos);
  EXPECT_LT(at("## Sensitivity (Sobol"), at("## Over all 32 cells"));
  EXPECT_LT(at("## Over all 32 cells"), at("## Validation errors"));
  EXPECT_LT(at("## Validation errors"), at("## Cells"));
  for (const char* role :
       {"| minimum |", "| lower quartile |", "| median |", "| upper quartile |", "| maximum |"})
    EXPECT_THAT(md, HasSubstr(role));
}

// The roles agree with an independent ranking of validation.csv's means, the per-cell tables
// show those cells alone, and the files keep every cell.
TEST_F(LargeStudy, TheChosenCellsAreTheQuartilesOfTheFilesAndTheFilesKeepEveryCell) {
  std::map<std::string, double> error;  // cell id → mean of the three axes' mean RMS position
  std::map<std::string, std::string> label;
  const CsvTable csv = ReadCsv(dir_ + "/run/tables/validation.csv");
  const int id = csv.Column("cell_id"), name = csv.Column("cell_label"),
            model = csv.Column("model"), metric = csv.Column("metric"), mean = csv.Column("mean");
  for (std::size_t r = 0; r < csv.rows.size(); ++r) {
    const auto& f = csv.rows[r];
    if (f[model] != "identified" || f[metric] != "rms_pos") continue;
    error[f[id]] += csv.Number(r, mean) / 3;
    label[f[id]] = f[name];
  }
  ASSERT_EQ(error.size(), 32u);
  const auto j = nlohmann::json::parse(Table("summary.json"));
  ASSERT_EQ(j["cells"].size(), 32u);
  std::vector<std::string> shown = j["shown_cells"].get<std::vector<std::string>>();
  ASSERT_EQ(shown.size(), 5u);
  const auto by_error = [&](const std::string& a, const std::string& b) {
    return error[a] < error[b];
  };
  const auto lowest = std::min_element(error.begin(), error.end(), [](auto& a, auto& b) {
                        return a.second < b.second;
                      })->first;
  const auto highest = std::max_element(error.begin(), error.end(), [](auto& a, auto& b) {
                         return a.second < b.second;
                       })->first;
  EXPECT_EQ(*std::min_element(shown.begin(), shown.end(), by_error), lowest);
  EXPECT_EQ(*std::max_element(shown.begin(), shown.end(), by_error), highest);
  // The validation table of summary.md has the shown cells' rows and no other cell's.
  const std::string md = Table("summary.md");
  const std::string validation = md.substr(md.find("## Validation errors"));
  for (const auto& [id, text] : label) {
    const bool is_shown = std::find(shown.begin(), shown.end(), id) != shown.end();
    EXPECT_EQ(validation.find("| " + text + " | x |") != std::string::npos, is_shown) << text;
  }
  EXPECT_EQ(ReadCsv(dir_ + "/run/tables/cells.csv").rows.size(), 32u);
}

}  // namespace
}  // namespace lrcal
