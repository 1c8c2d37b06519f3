// A plain table of strings rendered as aligned text, Markdown, CSV or LaTeX. Units belong in the
// column headers ("RMS pos (mm)"): every table lrcal prints says its units.
#pragma once

#include <string>
#include <vector>

namespace lrcal {

class Table {
 public:
  explicit Table(std::vector<std::string> header, std::string title = "")
      : title_(std::move(title)), header_(std::move(header)) {}
  void AddRow(std::vector<std::string> row) { rows_.push_back(std::move(row)); }
  int num_rows() const { return static_cast<int>(rows_.size()); }
  const std::string& title() const { return title_; }
  std::string ToText() const;
  std::string ToMarkdown() const;
  std::string ToCsv() const;
  std::string ToLatex() const;

 private:
  std::string title_;
  std::vector<std::string> header_;
  std::vector<std::vector<std::string>> rows_;
};

/// Fixed-point formatting with `digits` decimals ("—" for NaN).
std::string Fixed(double value, int digits = 4);

}  // namespace lrcal
