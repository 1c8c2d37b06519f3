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
  /// Adds a row of exactly one cell per header column (std::logic_error otherwise: a table
  /// whose rows and header disagree is a programming error).
  void AddRow(std::vector<std::string> row);
  int num_rows() const { return static_cast<int>(rows_.size()); }
  const std::string& title() const { return title_; }
  const std::vector<std::string>& header() const { return header_; }
  const std::vector<std::vector<std::string>>& rows() const { return rows_; }
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
