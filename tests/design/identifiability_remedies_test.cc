// The remedies for a rank-deficient set-up, against what the geometry says must happen: a
// common spin of all estimated planes about z0 is recovered by fixing θ1 or by a known vertical
// surface, never by a horizontal one or by another estimated plane; a common shift along z0 by
// fixing d1, knowing an offset or a known horizontal surface; the ranger's offset (a translation
// along the beam, like d6) by nothing but fixing one of the two; the ranger's scale against one
// plane by a second known plane.
#include "lrcal/design/identifiability_remedies.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "test_util.h"

namespace lrcal {
namespace {

// Three planes: horizontal (z0 = -0.3 m), x0 = -0.9 m and y0 = -0.9 m.
PlaneSet ThreePlanes() {
  return PlaneSet({Plane::FromCoefficients(0, 0, 1, 0.3), Plane::FromCoefficients(1, 0, 0, 0.9),
                   Plane::FromCoefficients(0, 1, 0, 0.9)},
                  {});
}

TargetedConfigurations OnEachPlane(const PlaneSet& planes, int per_plane) {
  TargetedConfigurations out(6);
  for (int p = 0; p < planes.size(); ++p) {
    const TargetedConfigurations c = testing::HittingConfigurations(planes[p], per_plane, 40 + p);
    for (int i = 0; i < c.size(); ++i) out.Add(c.q(i), p);
  }
  return out;
}

// The index of the lost direction whose text contains `name` and not `unless`, or -1.
int LostIndex(const RemedyReport& r, const std::string& name, const std::string& unless = "@") {
  for (std::size_t d = 0; d < r.lost.size(); ++d)
    if (r.lost[d].find(name) != std::string::npos && r.lost[d].find(unless) == std::string::npos)
      return static_cast<int>(d);
  return -1;
}

// Whether a remedy of `kind` whose plane faces base axis `axis` (or any, -1) recovers d.
bool Recovers(const RemedyReport& r, Remedy::Kind kind, int axis, int d) {
  for (const auto& m : r.remedies) {
    if (m.kind != kind) continue;
    if (axis >= 0 && std::abs(m.plane.normal[axis]) < 0.99) continue;
    if (std::find(m.recovers.begin(), m.recovers.end(), d) != m.recovers.end()) return true;
  }
  return false;
}

bool AnyTried(const RemedyReport& r, Remedy::Kind kind) {
  return std::any_of(r.remedies.begin(), r.remedies.end(),
                     [&](const Remedy& m) { return m.kind == kind; });
}

RemedyOptions Options() {
  RemedyOptions o;
  o.ranger = testing::PaperRig().ranger;
  return o;
}

TEST(IdentifiabilityRemedies, ThreeEstimatedPlanesLoseASpinAndAShift) {
  const RobotModel& robot = testing::PaperRobot();
  const PlaneSet planes = ThreePlanes();
  const MeasurementModel model(
      robot, planes,
      MakeParameterSet(robot, std::vector<PlaneTerms>(3, PlaneTerms{true, true}), {}));
  const TargetedConfigurations configs = OnEachPlane(planes, 40);
  const IdentifiabilityReport report = AnalyzeIdentifiability(model, configs);
  ASSERT_EQ(report.num_params(), 34);
  ASSERT_EQ(report.rank, 32);
  const RemedyReport r = FindRemedies(model, configs, report, Options());
  ASSERT_EQ(r.lost.size(), 2u) << r.ToString();
  const int spin = LostIndex(r, "theta1"), shift = LostIndex(r, "d1");
  ASSERT_GE(spin, 0) << r.ToString();
  ASSERT_GE(shift, 0) << r.ToString();
  ASSERT_TRUE(AnyTried(r, Remedy::Kind::kAddPlane)) << r.ToString();
  // Cheapest: fixing a parameter of each direction (nothing new on the rig).
  for (int d : {spin, shift}) {
    ASSERT_GE(r.cheapest[d], 0) << r.ToString();
    EXPECT_EQ(r.remedies[r.cheapest[d]].kind, Remedy::Kind::kFixParameter) << r.ToString();
  }
  // The spin: a known vertical surface sees it, a known horizontal one does not; the shift: the
  // other way round. Another estimated plane, whatever its orientation, sees neither.
  EXPECT_TRUE(Recovers(r, Remedy::Kind::kAddKnownDistance, 0, spin)) << r.ToString();
  EXPECT_TRUE(Recovers(r, Remedy::Kind::kAddKnownDistance, 1, spin)) << r.ToString();
  EXPECT_FALSE(Recovers(r, Remedy::Kind::kAddKnownDistance, 2, spin)) << r.ToString();
  EXPECT_TRUE(Recovers(r, Remedy::Kind::kAddKnownDistance, 2, shift)) << r.ToString();
  EXPECT_FALSE(Recovers(r, Remedy::Kind::kAddKnownDistance, 0, shift)) << r.ToString();
  EXPECT_FALSE(Recovers(r, Remedy::Kind::kAddPlane, -1, spin)) << r.ToString();
  EXPECT_FALSE(Recovers(r, Remedy::Kind::kAddPlane, -1, shift)) << r.ToString();
  // Knowing the horizontal plane's offset recovers the shift, not the spin.
  for (const auto& m : r.remedies) {
    if (m.kind != Remedy::Kind::kKnowPlaneOffset) continue;
    EXPECT_EQ(m.parameter, "plane1_f") << r.ToString();
    EXPECT_EQ(m.recovers, std::vector<int>{shift}) << r.ToString();
  }
  EXPECT_THAT(r.ToString(), ::testing::HasSubstr("cheapest fix: fix")) << r.ToString();
}

TEST(IdentifiabilityRemedies, RangerOffsetOnlyByFixingAndScaleByASecondKnownPlane) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(
      robot, testing::PaperPlane(),
      MakeParameterSet(robot, PlaneTerms{}, {}, "--fix", RangerTerms{true, true}));
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(80, 4);
  const IdentifiabilityReport report = AnalyzeIdentifiability(model, configs);
  ASSERT_EQ(report.rank, 25);
  const RemedyReport r = FindRemedies(model, configs, report, Options());
  // Which parameter of each pair the analysis calls dependent depends on the configurations:
  // the directions are told apart by their members (the scale's involves the lengths).
  const int offset = LostIndex(r, "ranger_offset", "ranger_scale");
  const int scale = LostIndex(r, "ranger_scale");
  ASSERT_GE(offset, 0) << r.ToString();
  ASSERT_GE(scale, 0) << r.ToString();
  // The offset is a re-labelling of d6: no plane of any kind separates them.
  EXPECT_FALSE(Recovers(r, Remedy::Kind::kAddPlane, -1, offset)) << r.ToString();
  EXPECT_EQ(r.remedies[r.cheapest[offset]].kind, Remedy::Kind::kFixParameter);
  // The scale: a second known plane of some orientation separates it from the arm's lengths.
  EXPECT_TRUE(Recovers(r, Remedy::Kind::kAddPlane, -1, scale)) << r.ToString();
  // With the planes known, an added plane is already a known surface: not listed twice.
  EXPECT_FALSE(AnyTried(r, Remedy::Kind::kAddKnownDistance)) << r.ToString();
}

TEST(IdentifiabilityRemedies, FullRankNeedsNothing) {
  const RobotModel& robot = testing::PaperRobot();
  const MeasurementModel model(robot, testing::PaperPlane(), MakeParameterSet(robot, PlaneTerms{}));
  const TargetedConfigurations configs = testing::PaperHittingConfigurations(60, 4);
  const IdentifiabilityReport report = AnalyzeIdentifiability(model, configs);
  ASSERT_TRUE(report.full_rank());
  const RemedyReport r = FindRemedies(model, configs, report, Options());
  EXPECT_TRUE(r.lost.empty());
  EXPECT_TRUE(r.remedies.empty());
}

}  // namespace
}  // namespace lrcal
