#include "lrcal/core/text_table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

namespace lrcal {

std::string Fixed(double value, int digits) {
  if (std::isnan(value)) return "—";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, value);
  return buf;
}

namespace {
// Display width in characters (UTF-8 continuation bytes do not count).
std::size_t Width(const std::string& s) {
  std::size_t w = 0;
  for (unsigned char c : s)
    if ((c & 0xC0) != 0x80) ++w;
  return w;
}
}  // namespace

void Table::AddRow(std::vector<std::string> row) {
  if (row.size() != header_.size())
    throw std::logic_error("table '" +
                           (!title_.empty()   ? title_
                            : header_.empty() ? std::string("?")
                                              : header_.front()) +
                           "': a row of " + std::to_string(row.size()) + " cells under " +
                           std::to_string(header_.size()) + " columns");
  rows_.push_back(std::move(row));
}

std::string Table::ToText() const {
  std::vector<std::size_t> w(header_.size());
  for (std::size_t c = 0; c < header_.size(); ++c) w[c] = Width(header_[c]);
  for (const auto& r : rows_)
    for (std::size_t c = 0; c < r.size() && c < w.size(); ++c) w[c] = std::max(w[c], Width(r[c]));
  std::ostringstream out;
  if (!title_.empty()) out << title_ << "\n";
  auto line = [&](const std::vector<std::string>& r) {
    for (std::size_t c = 0; c < w.size(); ++c) {
      const std::string cell = c < r.size() ? r[c] : "";
      out << (c ? "  " : "") << std::string(w[c] - Width(cell), ' ') << cell;
    }
    out << "\n";
  };
  line(header_);
  std::size_t total = 0;
  for (auto x : w) total += x + 2;
  out << std::string(total > 2 ? total - 2 : 0, '-') << "\n";
  for (const auto& r : rows_) line(r);
  return out.str();
}

std::string Table::ToMarkdown() const {
  std::ostringstream out;
  if (!title_.empty()) out << "**" << title_ << "**\n\n";
  out << "|";
  for (const auto& h : header_) out << " " << h << " |";
  out << "\n|";
  for (std::size_t c = 0; c < header_.size(); ++c) out << (c == 0 ? "---|" : "---:|");
  out << "\n";
  for (const auto& r : rows_) {
    out << "|";
    for (const auto& cell : r) out << " " << cell << " |";
    out << "\n";
  }
  return out.str();
}

std::string Table::ToCsv() const {
  auto quote = [](const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
  };
  std::ostringstream out;
  for (std::size_t c = 0; c < header_.size(); ++c) out << (c ? "," : "") << quote(header_[c]);
  out << "\n";
  for (const auto& r : rows_) {
    for (std::size_t c = 0; c < r.size(); ++c) out << (c ? "," : "") << quote(r[c]);
    out << "\n";
  }
  return out.str();
}

std::string Table::ToLatex() const {
  auto esc = [](const std::string& s) {
    std::string o;
    for (char c : s) {
      if (c == '%' || c == '&' || c == '_' || c == '#') o += '\\';
      o += c;
    }
    return o;
  };
  std::ostringstream out;
  out << "\\begin{table}\n\\centering\n";
  if (!title_.empty()) out << "\\caption{" << esc(title_) << "}\n";
  out << "\\begin{tabular}{l" << std::string(header_.size() > 0 ? header_.size() - 1 : 0, 'r')
      << "}\n\\hline\n";
  for (std::size_t c = 0; c < header_.size(); ++c) out << (c ? " & " : "") << esc(header_[c]);
  out << " \\\\\n\\hline\n";
  for (const auto& r : rows_) {
    for (std::size_t c = 0; c < r.size(); ++c) out << (c ? " & " : "") << esc(r[c]);
    out << " \\\\\n";
  }
  out << "\\hline\n\\end{tabular}\n\\end{table}\n";
  return out.str();
}

}  // namespace lrcal
