// A short document of headings, paragraphs, notes and tables, rendered as Markdown (summary.md)
// or as a list of JSON blocks that another program lays out without parsing Markdown back (the
// report page of lrcal.report reads RUN_DIR/report/document.json).
#pragma once

#include <string>
#include <vector>

#include "lrcal/core/json.h"
#include "lrcal/core/text_table.h"

namespace lrcal {

class TextDocument {
 public:
  /// What a block is. Paragraph text may hold `code` spans (backquotes), nothing else of
  /// Markdown; a note is a paragraph shown in bold (a warning, such as a partial run).
  enum class BlockKind { kTitle, kHeading, kParagraph, kNote, kTable };

  void AddTitle(std::string text) { Add(BlockKind::kTitle, std::move(text)); }
  void AddHeading(std::string text) { Add(BlockKind::kHeading, std::move(text)); }
  void AddParagraph(std::string text) { Add(BlockKind::kParagraph, std::move(text)); }
  void AddNote(std::string text) { Add(BlockKind::kNote, std::move(text)); }
  void AddTable(Table table);
  /// Appends every block of `other`.
  void Append(const TextDocument& other);

  bool empty() const { return blocks_.empty(); }

  /// Markdown: "# title", "## heading", paragraphs, "**note**", pipe tables (table.h), each block
  /// on its own lines and blocks separated by one blank line.
  std::string ToMarkdown() const;
  /// {"blocks": [{"kind": "title" | "heading" | "paragraph" | "note", "text": ...},
  ///             {"kind": "table", "title": ..., "header": [...], "rows": [[...], ...]}]}.
  Json ToJson() const;

 private:
  struct Block {
    BlockKind kind;
    std::string text;
    int table = -1;  ///< index into tables_ for kTable
  };
  void Add(BlockKind kind, std::string text) { blocks_.push_back({kind, std::move(text), -1}); }

  std::vector<Block> blocks_;
  std::vector<Table> tables_;
};

}  // namespace lrcal
