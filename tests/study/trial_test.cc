// The trial pipeline's cell preparation: the design certificate a study states against the one
// `lrcal design` states for the same design.
#include <gtest/gtest.h>

#include <fstream>

#include "lrcal/design/design_certificate.h"
#include "lrcal/design/experiment_design.h"
#include "lrcal/study/study.h"
#include "study/trial_pipeline.h"
#include "test_util.h"
#include "trial_checks.h"

namespace lrcal {
namespace {

TEST(CellPreparation, TheStudysCertificateIsLrcalDesignsWithinItsStatedTolerance) {
  // The study certifies with 300 relaxation steps, lrcal design with 1500: a looser bound, so a
  // lower (still valid) efficiency, by at most 0.3 percentage points (trial.cc).
  constexpr double kFewerStepsTolerance = 0.003;
  const std::string dir = testing::TempDir("cell_certificate");
  std::ofstream(dir + "/s.yaml") << "name: c\nseed: 1\ntrials: 1\nrobot: "
                                 << testing::SourcePath("studies/robots/paper.yaml")
                                 << "\npool: {size: 101}\nvalidation: {size: 5}\n"
                                    "sweep:\n  axes:\n    - key: selection.count\n"
                                    "      values: [30, 50]\n";
  const Study study = LoadStudy(dir + "/s.yaml");
  for (const Cell& cell : study.cells) {
    const auto c = PrepareCell(study, cell);
    const Eigen::MatrixXd G = DesignJacobian(*c->model, c->pool, DesignScaling::kSI, 0, 0);
    const DesignCertificate design = CertifyDesign(G, c->design.slots, DesignCriterion::kE);
    ASSERT_TRUE(design.available);
    EXPECT_LE(c->design_efficiency, design.efficiency + 1e-12) << cell.label;
    EXPECT_NEAR(c->design_efficiency, design.efficiency, kFewerStepsTolerance) << cell.label;
  }
}

// Cells that differ only in noise share their design's certificate (a memo in trial.cc): each
// cell's is still bit for bit the certificate of its own G and design, whichever cell computed it.
TEST(CellPreparation, SharedCertificatesAreEachCellsOwn) {
  const std::string dir = testing::TempDir("cell_certificate_memo");
  std::ofstream(dir + "/s.yaml") << "name: c\nseed: 1\ntrials: 1\nrobot: "
                                 << testing::SourcePath("studies/robots/paper.yaml")
                                 << "\npool: {size: 101}\nvalidation: {size: 5}\n"
                                    "sweep:\n  axes:\n    - key: selection.count\n"
                                    "      values: [30, 50]\n    - key: noise.sigma_mm\n"
                                    "      values: [0.1, 0.3]\n    - key: pool.size\n"
                                    "      values: [101, 120]\n";
  const Study study = LoadStudy(dir + "/s.yaml");
  ASSERT_EQ(study.cells.size(), 8u);
  for (const Cell& cell : study.cells) {
    const auto c = PrepareCell(study, cell);
    const Eigen::MatrixXd G = DesignJacobian(*c->model, c->pool, DesignScaling::kSI, 0, 0);
    const DesignCertificate own = CertifyDesign(G, c->design.slots, DesignCriterion::kE, 300);
    ASSERT_TRUE(own.available);
    EXPECT_EQ(c->design_efficiency, own.efficiency) << cell.label;
  }
}

// A resume prepares a cell whose row is stored for its trials alone (runner.cc): the same trials,
// bit for bit, for a cell with a fixed truth, a drawn one, and coverage stated per trial.
TEST(CellPreparation, ACellPreparedForItsTrialsAloneRunsTheSameTrials) {
  const std::string dir = testing::TempDir("cell_for_trials");
  std::ofstream(dir + "/s.yaml") << "name: c\nseed: 3\ntrials: 1\nrobot: "
                                 << testing::SourcePath("studies/robots/paper.yaml")
                                 << "\npool: {size: 101}\nselection: {count: 30}\n"
                                    "validation: {size: 8, coverage: true}\n"
                                    "sweep:\n  axes:\n    - key: truth.mode\n"
                                    "      values: [robot_file, random]\n";
  const Study study = LoadStudy(dir + "/s.yaml");
  ASSERT_EQ(study.cells.size(), 2u);
  for (const Cell& cell : study.cells) {
    SCOPED_TRACE(cell.label);
    testing::ExpectForTrialsPreparesTheSameTrials(study, cell, 3);
  }
}

}  // namespace
}  // namespace lrcal
