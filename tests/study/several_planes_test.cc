// Studies on several planes: a plane list splits the pool and validation draws by share, each
// configuration's beam hits its own plane, a per-plane `estimate` sets that plane's terms, a pool
// file's plane column is resolved against the list (and refused when it names a plane not
// listed), and a validation file's plane column is not read.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "lrcal/core/error.h"
#include "lrcal/measurement/simulation.h"
#include "lrcal/study/study.h"
#include "study/trial_pipeline.h"
#include "test_util.h"

namespace lrcal {
namespace {

constexpr const char* kTwoPlanes =
    "plane:\n"
    "  - {normal: [0, 1, 4.6], offset: -0.69, name: paper, share: 2}\n"
    "  - {normal: [1, 0, 0], offset: 0.9, name: wall, estimate: offset}\n";

std::string WritePlanesStudy(const std::string& dir, const std::string& body) {
  const std::string path = dir + "/s.yaml";
  std::ofstream(path) << "name: planes\nseed: 3\ntrials: 5\nrobot: paper\n"
                         "selection: {count: 40}\n"
                      << body;
  return path;
}

int CountOn(const TargetedConfigurations& c, int plane) {
  int n = 0;
  for (int i = 0; i < c.size(); ++i) n += c.target(i) == plane;
  return n;
}

TEST(SeveralPlanes, ThePoolIsSplitByShareAndEveryBeamHitsItsPlane) {
  const std::string dir = testing::TempDir("several_planes_split");
  const Study study = LoadStudy(WritePlanesStudy(
      dir, std::string(kTwoPlanes) + "pool: {size: 61}\nvalidation: {size: 10}\n"));
  const auto c = PrepareCell(study, study.cells[0]);
  ASSERT_EQ(c->planes.size(), 2);
  EXPECT_EQ(c->planes.name(1), "wall");
  // 61 in the ratio 2:1 by largest remainders: 40.67 → 41 and 20.33 → 20.
  EXPECT_EQ(CountOn(c->pool, 0), 41);
  EXPECT_EQ(CountOn(c->pool, 1), 20);
  std::vector<double> h;
  std::vector<BeamMiss> misses;
  ExactReadings(*c->robot, c->robot->nominal_values(), c->planes, c->ranger, c->pool, &h, &misses);
  for (int i = 0; i < c->pool.size(); ++i) EXPECT_EQ(misses[i], BeamMiss::kNone) << i;
  // The wall's offset is estimated, the paper plane's terms are not: 25 + 1 parameters.
  const ParameterSet& ps = c->model->parameters();
  EXPECT_EQ(ps.size(), 26);
  EXPECT_EQ(ps.names.back(), "plane2_f");
  EXPECT_EQ(ps.plane_columns[0].f, -1);
}

TEST(SeveralPlanes, PoolFilePlaneColumnIsResolvedAndValidationsIgnored) {
  const std::string dir = testing::TempDir("several_planes_files");
  // 30 hitting configurations on each plane, the wall's named, the paper's numbered.
  const PlaneSet planes({testing::PaperPlane(), Plane::FromCoefficients(1, 0, 0, 0.9)}, {});
  {
    std::ofstream pool(dir + "/pool.csv");
    pool.precision(17);
    pool << "q1,q2,q3,q4,q5,q6,plane\n";
    for (int p = 0; p < 2; ++p) {
      const TargetedConfigurations c = testing::HittingConfigurations(planes[p], 30, 7 + p);
      for (int i = 0; i < c.size(); ++i) {
        for (int j = 0; j < 6; ++j) pool << c.q(i)[j] << ",";
        pool << (p == 0 ? "1" : "wall") << "\n";
      }
    }
    std::ofstream(dir + "/val.csv") << "q1,q2,q3,q4,q5,q6,plane\n0.1,-0.7,0.2,0,0.3,0,9\n"
                                       "0.2,-0.5,0.1,0.4,0.3,0.2,9\n";
  }
  const Study study = LoadStudy(WritePlanesStudy(
      dir, std::string(kTwoPlanes) + "pool: {file: pool.csv}\nvalidation: {file: val.csv}\n"));
  const auto c = PrepareCell(study, study.cells[0]);
  // Rows whose true beam misses are dropped; the rest keep their plane.
  EXPECT_LE(c->pool.size(), 60);
  EXPECT_GT(CountOn(c->pool, 0), 20);
  EXPECT_GT(CountOn(c->pool, 1), 20);
  EXPECT_EQ(c->validation.size(), 2);

  // A pool naming a plane the study does not list is refused, naming the file's line.
  std::ofstream(dir + "/pool.csv", std::ios::app) << "0,0,0,0,0,0,ceiling\n";
  const Study bad = LoadStudy(WritePlanesStudy(
      dir, std::string(kTwoPlanes) + "pool: {file: pool.csv}\nvalidation: {file: val.csv}\n"));
  try {
    PrepareCell(bad, bad.cells[0]);
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(std::string(e.what()),
                ::testing::HasSubstr("pool.csv:62 column 'plane': 'ceiling' is not one of"))
        << e.what();
  }
}

// The shipped study (README "Several planes"): 3 × 4 × 5 × 2 cells; its last cell has three
// planes, every normal and offset estimated, θ1 and d1 fixed: 23 + 9 parameters.
TEST(SeveralPlanes, ShippedStudyLoadsWithItsCells) {
  const Study study = LoadStudy(testing::SourcePath("studies/planes.yaml"));
  ASSERT_EQ(study.cells.size(), 120u);
  const auto c = PrepareCell(study, study.cells.back());
  EXPECT_EQ(c->planes.size(), 3);
  EXPECT_EQ(c->model->num_parameters(), 23 + 9);
  EXPECT_EQ(c->design.configs.size(), 50);
  for (int p = 0; p < 3; ++p) EXPECT_EQ(CountOn(c->pool, p), 40) << p;
}

}  // namespace
}  // namespace lrcal
