// Text utilities: angle expressions and list splitting.
#include "lrcal/core/strings.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lrcal {
namespace {

TEST(Strings, AngleExpressions) {
  double v = 0;
  ASSERT_TRUE(ParseAngleExpression("-pi/2", &v));
  EXPECT_DOUBLE_EQ(v, -M_PI / 2);
  ASSERT_TRUE(ParseAngleExpression("3*pi/4", &v));
  EXPECT_DOUBLE_EQ(v, 3 * M_PI / 4);
  ASSERT_TRUE(ParseAngleExpression("1.25e-1", &v));
  EXPECT_DOUBLE_EQ(v, 0.125);
  EXPECT_FALSE(ParseAngleExpression("pie", &v));
  EXPECT_FALSE(ParseAngleExpression("pi/0", &v));
}

TEST(Strings, SplitListTrimsItemsAndKeepsEmptyOnes) {
  EXPECT_EQ(SplitList(""), std::vector<std::string>{});
  EXPECT_EQ(SplitList(" a, b ,c"), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(SplitList("a,,b"), (std::vector<std::string>{"a", "", "b"}));
  EXPECT_EQ(SplitList("x;y", ';'), (std::vector<std::string>{"x", "y"}));
}

}  // namespace
}  // namespace lrcal
