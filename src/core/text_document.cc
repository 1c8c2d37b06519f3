#include "lrcal/core/text_document.h"

#include <sstream>

namespace lrcal {

void TextDocument::AddTable(Table table) {
  blocks_.push_back({BlockKind::kTable, "", static_cast<int>(tables_.size())});
  tables_.push_back(std::move(table));
}

void TextDocument::Append(const TextDocument& other) {
  for (const Block& b : other.blocks_) {
    if (b.kind == BlockKind::kTable)
      AddTable(other.tables_[b.table]);
    else
      Add(b.kind, b.text);
  }
}

std::string TextDocument::ToMarkdown() const {
  std::ostringstream out;
  for (std::size_t i = 0; i < blocks_.size(); ++i) {
    const Block& b = blocks_[i];
    if (i > 0) out << "\n";
    switch (b.kind) {
      case BlockKind::kTitle:
        out << "# " << b.text << "\n";
        break;
      case BlockKind::kHeading:
        out << "## " << b.text << "\n";
        break;
      case BlockKind::kParagraph:
        out << b.text << "\n";
        break;
      case BlockKind::kNote:
        out << "**" << b.text << "**\n";
        break;
      case BlockKind::kTable:
        out << tables_[b.table].ToMarkdown();
        break;
    }
  }
  return out.str();
}

Json TextDocument::ToJson() const {
  static const char* const kKinds[] = {"title", "heading", "paragraph", "note", "table"};
  Json blocks = Json::array();
  for (const Block& b : blocks_) {
    Json j = {{"kind", kKinds[static_cast<int>(b.kind)]}};
    if (b.kind == BlockKind::kTable) {
      const Table& t = tables_[b.table];
      j["title"] = t.title();
      j["header"] = t.header();
      j["rows"] = t.rows();
    } else {
      j["text"] = b.text;
    }
    blocks.push_back(std::move(j));
  }
  return {{"blocks", std::move(blocks)}};
}

}  // namespace lrcal
