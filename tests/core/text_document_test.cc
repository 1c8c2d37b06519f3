// TextDocument: the Markdown it renders (summary.md's layout: one blank line between blocks) and
// the JSON blocks the report page lays out, from the same calls.
#include "lrcal/core/text_document.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace lrcal {
namespace {

using ::testing::ElementsAre;

TextDocument Example() {
  TextDocument doc;
  doc.AddTitle("Study `quick`");
  doc.AddParagraph("Seed 7.");
  doc.AddNote("Partial run.");
  doc.AddHeading("Cells");
  Table t({"cell", "RMS pos (mm)"}, "Cell A");
  t.AddRow({"case 1", "0.0636"});
  doc.AddTable(t);
  doc.AddParagraph("After the table.");
  return doc;
}

TEST(TextDocument, MarkdownSeparatesBlocksByOneBlankLine) {
  EXPECT_EQ(Example().ToMarkdown(),
            "# Study `quick`\n\nSeed 7.\n\n**Partial run.**\n\n## Cells\n\n**Cell A**\n\n"
            "| cell | RMS pos (mm) |\n|---|---:|\n| case 1 | 0.0636 |\n\nAfter the table.\n");
}

TEST(TextDocument, JsonHasEveryBlockWithItsKindAndTheTablesCells) {
  const Json j = Example().ToJson();
  ASSERT_EQ(j["blocks"].size(), 6U);
  EXPECT_EQ(j["blocks"][0], Json({{"kind", "title"}, {"text", "Study `quick`"}}));
  EXPECT_EQ(j["blocks"][2]["kind"], "note");
  const Json& table = j["blocks"][4];
  EXPECT_EQ(table["kind"], "table");
  EXPECT_EQ(table["title"], "Cell A");
  EXPECT_THAT(table["header"].get<std::vector<std::string>>(), ElementsAre("cell", "RMS pos (mm)"));
  EXPECT_EQ(table["rows"], Json::parse(R"([["case 1", "0.0636"]])"));
}

TEST(TextDocument, AppendKeepsTheOrderAndTheTables) {
  TextDocument doc;
  doc.AddHeading("First");
  doc.Append(Example());
  EXPECT_EQ(doc.ToMarkdown(), "## First\n\n" + Example().ToMarkdown());
  EXPECT_EQ(doc.ToJson()["blocks"].size(), 7U);
}

TEST(Table, ARowMustHaveOneCellPerColumn) {
  Table t({"a", "b"}, "T");
  EXPECT_THROW(t.AddRow({"1"}), std::logic_error);
  EXPECT_THROW(t.AddRow({"1", "2", "3"}), std::logic_error);
  t.AddRow({"1", "2"});
  EXPECT_EQ(t.num_rows(), 1);
}

}  // namespace
}  // namespace lrcal
