// Bad inputs as a new user makes them, one row each: the exit code, and that the message names
// the file, line and key (or the option) and what was expected. A few legitimate inputs that
// used to be refused are here too (exit 0). Placeholders in files and arguments:
//   {dir}    the case's own temporary folder (files are written there)
//   {robot}  studies/robots/paper.yaml      {study}  a valid small study file's header
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "test_util.h"

namespace lrcal {
namespace {

struct BadInput {
  std::string name;
  std::map<std::string, std::string> files;  // name in {dir} → content
  std::string args;                          // the lrcal command line
  int exit_code;
  std::vector<std::string> expected;  // substrings of the output, all required
  std::string setup = "";             // shell command run first (in {dir})
};
void PrintTo(const BadInput& b, std::ostream* os) { *os << b.name; }

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t p = 0; (p = s.find(from, p)) != std::string::npos; p += to.size())
    s.replace(p, from.size(), to);
  return s;
}

const char* kConfigs = "q1,q2,q3,q4,q5,q6\n0.1,0.2,0.3,0.4,0.5,0.6\n";
const char* kStudy = "name: s\nseed: 1\ntrials: 3\nrobot: {robot}\n";
const char* kTwoLinkRobot =
    "name: two\nlinks:\n  - {theta: 0, alpha: 0, a: 0.5, d: 0, parameters: [theta, a]}\n"
    "  - {theta: 0, alpha: 0, a: 0.4, d: 0, parameters: [theta, a]}\n";

class BadInputTest : public ::testing::TestWithParam<BadInput> {};

TEST_P(BadInputTest, ExitCodeAndMessageNameWhereAndWhat) {
  const BadInput& c = GetParam();
  const std::string dir = testing::TempDir("bad_" + c.name);
  const auto fill = [&](const std::string& s) {
    std::string out = Replace(Replace(s, "{study}", kStudy), "{dir}", dir);
    out = Replace(out, "{lrcal}", testing::LrcalBinary());
    return Replace(out, "{robot}", testing::SourcePath("studies/robots/paper.yaml"));
  };
  for (const auto& [name, content] : c.files) {
    std::ofstream out(dir + "/" + name, std::ios::binary);
    out << fill(content);
  }
  std::string out;
  if (!c.setup.empty()) testing::RunCommand("cd " + dir + " && " + fill(c.setup), &out);
  const int code = testing::RunCommand(
      "cd " + dir + " && " + testing::LrcalBinary() + " " + fill(c.args), &out);
  EXPECT_EQ(code, c.exit_code) << out;
  for (const std::string& e : c.expected)
    EXPECT_NE(out.find(fill(e)), std::string::npos) << "expected '" << fill(e) << "' in:\n" << out;
}

std::string Nul() { return std::string("q1,q2,q3,q4,q5,q6\n0.1\0garbage,0,0,0,0,0\n", 39); }

const std::vector<BadInput>& Cases() {
  static const std::vector<BadInput> cases = {
      // ---- CSV files ---------------------------------------------------------------------
      {"CsvEmpty", {{"c.csv", ""}}, "kinematics --configs c.csv", 2, {"c.csv: empty file"}},
      {"CsvOnlyComments", {{"c.csv", "# nothing\n\n"}}, "kinematics --configs c.csv", 2,
       {"c.csv: empty file"}},
      {"CsvIsADirectory", {}, "kinematics --configs {dir}", 2, {"is a directory"}, "true"},
      {"CsvMissing", {}, "kinematics --configs none.csv", 2, {"none.csv: cannot open file"}},
      {"CsvRepeatedJointColumn", {{"c.csv", "q1,q2,q1,q4,q5,q6\n0,0,0,0,0,0\n"}},
       "kinematics --configs c.csv", 2, {"c.csv:1 column 'q1'", "columns 1 and 3"}},
      {"CsvRepeatedH",
       {{"m.csv", "q1,q2,q3,q4,q5,q6,h,h\n0,0,0,0,0,0,1,1\n"}},
       "identify --data m.csv", 2, {"m.csv:1 column 'h'", "columns 7 and 8"}},
      {"CsvHugeJointIndex", {{"c.csv", "q1,q2,q3,q4,q5,q6,q99999999999\n0,0,0,0,0,0,0\n"}},
       "kinematics --configs c.csv", 2, {"column 'q99999999999'", "only 6 joints"}},
      {"CsvNulByte", {{"c.csv", Nul()}}, "kinematics --configs c.csv", 2,
       {"c.csv:2", "NUL byte"}},
      {"CsvUnclosedQuote", {{"c.csv", "q1,q2,q3,q4,q5,q6\n\"0.1,0,0,0,0,0\n"}},
       "kinematics --configs c.csv", 2, {"c.csv:2", "not closed"}},
      {"CsvInfinity", {{"c.csv", "q1,q2,q3,q4,q5,q6\ninf,0,0,0,0,0\n"}},
       "kinematics --configs c.csv", 2, {"c.csv:2 column 'q1'", "expected a finite number"}},
      {"CsvNan", {{"c.csv", "q1,q2,q3,q4,q5,q6\n0,nan,0,0,0,0\n"}},
       "kinematics --configs c.csv", 2, {"c.csv:2 column 'q2'", "got 'nan'"}},
      {"CsvHexadecimal", {{"c.csv", "q1,q2,q3,q4,q5,q6\n0x10,0,0,0,0,0\n"}},
       "kinematics --configs c.csv", 2, {"c.csv:2 column 'q1'", "got '0x10'"}},
      {"CsvEmptyCell", {{"c.csv", "q1,q2,q3,q4,q5,q6\n0,,0,0,0,0\n"}},
       "kinematics --configs c.csv", 2, {"c.csv:2 column 'q2'", "got ''"}},
      {"CsvTooManyCells", {{"c.csv", "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0,0\n"}},
       "kinematics --configs c.csv", 2, {"c.csv:2: expected 6 cells", "got 7"}},
      {"CsvOnlyHeader", {{"c.csv", "q1,q2,q3,q4,q5,q6\n"}}, "identifiability --configs c.csv",
       2, {"c.csv: no configurations"}},
      {"CsvNoReadings", {{"m.csv", "q1,q2,q3,q4,q5,q6,h\n"}}, "identify --data m.csv", 2,
       {"m.csv: no readings"}},
      {"CsvZeroReading", {{"m.csv", "q1,q2,q3,q4,q5,q6,h\n0,0,0,0,0,0,0\n"}},
       "identify --data m.csv", 2, {"m.csv:2 column 'h'", "positive distance in m"}},
      {"CsvReadingOf1e300", {{"m.csv", "q1,q2,q3,q4,q5,q6,h\n0,0,0,0,0,0,1e300\n"}},
       "identify --data m.csv", 2, {"m.csv:2 column 'h'", "outside the ranger's range"}},
      {"CsvReadingsInMillimetres", {{"m.csv", "q1,q2,q3,q4,q5,q6,h\n0,0,0,0,0,0,750\n"}},
       "identify --data m.csv", 2, {"m.csv:2 column 'h'", "written in mm?"}},
      {"CsvTextInAJointColumn", {{"c.csv", "q1,q2,q3,q4,q5,q6\n0,0,0,zero,0,0\n"}},
       "kinematics --configs c.csv", 2, {"c.csv:2 column 'q4'", "got 'zero'"}},
      // Legitimate CSVs that used to be refused.
      {"CsvByteOrderMark", {{"c.csv", "\xEF\xBB\xBFq1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n"}},
       "kinematics --configs c.csv --format json", 0, {"\"position\""}},
      {"CsvCarriageReturnsOnly", {{"c.csv", "q1,q2,q3,q4,q5,q6\r0,0,0,0,0,0\r1,0,0,0,0,0\r"}},
       "kinematics --configs c.csv", 0, {"2  "}},
      {"CsvWindowsLineEnds", {{"c.csv", "q1,q2,q3,q4,q5,q6\r\n0,0,0,0,0,0\r\n"}},
       "kinematics --configs c.csv --format json", 0, {"\"position\""}},
      {"CsvQuotedHeaderAndValues", {{"c.csv", "\"q1\",\"q2\",q3,q4,q5,q6\n\"0.1\",0,0,0,0,0\n"}},
       "kinematics --configs c.csv --format json", 0, {"0.1"}},
      {"CsvExtraTextColumn",
       {{"c.csv", "q1,q2,q3,q4,q5,q6,operator,note\n0,0,0,0,0,0,alice,\"first, rough\"\n"}},
       "kinematics --configs c.csv --format json", 0, {"\"position\""}},
      {"CsvBlankLinesAndComments", {{"c.csv", "# logged 2026\nq1,q2,q3,q4,q5,q6\n\n0,0,0,0,0,0\n\n"}},
       "kinematics --configs c.csv --format json", 0, {"\"position\""}},
      // ---- Robot files -------------------------------------------------------------------
      {"RobotYamlSyntax", {{"r.yaml", "links: [\n"}}, "sample --robot r.yaml --out c.csv", 2,
       {"r.yaml:", "YAML syntax error"}},
      {"RobotIsADirectory", {}, "sample --robot {dir} --out c.csv", 2, {"is a directory"}},
      {"RobotNoLinks", {{"r.yaml", "name: x\n"}}, "sample --robot r.yaml --out c.csv", 2,
       {"r.yaml", "key 'links'", "non-empty list of links"}},
      {"RobotAngleOverflows",
       {{"r.yaml", "links:\n  - {theta: 1e999, alpha: 0, a: 0, d: 0, parameters: [theta]}\n"}},
       "sample --robot r.yaml --out c.csv", 2, {"r.yaml:2 key 'links[0].theta'", "finite number"}},
      {"RobotLengthOverflows",
       {{"r.yaml", "links:\n  - {theta: 0, alpha: 0, a: 1e400, d: 0, parameters: [theta]}\n"}},
       "sample --robot r.yaml --out c.csv", 2, {"r.yaml:2 key 'links[0].a'", "finite number"}},
      {"RobotVeryLongNumber",
       {{"r.yaml", "links:\n  - {theta: 0, alpha: 0, a: 1" + std::string(400, '0') +
                       ", d: 0, parameters: [theta]}\n"}},
       "sample --robot r.yaml --out c.csv", 2, {"key 'links[0].a'", "..."}},
      {"RobotRepeatedTopKey",
       {{"r.yaml", std::string(kTwoLinkRobot) + "name: again\n"}},
       "sample --robot r.yaml --out c.csv", 2, {"r.yaml:5 key 'name'", "repeated key"}},
      {"RobotComplexKey", {{"r.yaml", "? [a, b]\n: 1\n"}}, "sample --robot r.yaml --out c.csv",
       2, {"r.yaml:1", "expected a plain key"}},
      {"RobotUnknownJoint",
       {{"r.yaml",
         "links:\n  - {joint: spherical, theta: 0, alpha: 0, a: 0, d: 0, parameters: [a]}\n"}},
       "sample --robot r.yaml --out c.csv", 2, {"key 'links[0].joint'", "revolute or prismatic"}},
      {"RobotJointRangeReversed",
       {{"r.yaml",
         "links:\n  - {theta: 0, alpha: 0, a: 0, d: 0, parameters: [a], q_min: 1, q_max: 0}\n"}},
       "sample --robot r.yaml --out c.csv", 2, {"r.yaml:2", "q_min must be below q_max"}},
      {"RobotBadAngleUnit",
       {{"r.yaml", std::string(kTwoLinkRobot) +
                       "true_errors: {angle_unit: grad, links: [{}, {}]}\n"}},
       "sample --robot r.yaml --out c.csv", 2, {"true_errors.angle_unit", "rad, mrad or deg"}},
      {"RobotTrueErrorsPerLink",
       {{"r.yaml", std::string(kTwoLinkRobot) + "true_errors: {links: [{}]}\n"}},
       "sample --robot r.yaml --out c.csv", 2, {"true_errors.links", "one per link"}},
      {"RobotZeroPlaneNormal",
       {{"r.yaml", std::string(kTwoLinkRobot) + "plane: {normal: [0, 0, 0], offset: 1}\n"}},
       "sample --robot r.yaml --out c.csv", 2, {"r.yaml:5 key 'plane'", "zero"}},
      {"RobotRangerReversed",
       {{"r.yaml", std::string(kTwoLinkRobot) + "ranger: {min_range: 2, max_range: 1}\n"}},
       "sample --robot r.yaml --out c.csv", 2, {"key 'ranger'", "min_range < max_range"}},
      {"RobotIncidenceAbove90",
       {{"r.yaml", std::string(kTwoLinkRobot) + "ranger: {max_incidence_deg: 120}\n"}},
       "sample --robot r.yaml --out c.csv", 2, {"key 'ranger'", "(0, 90]"}},
      {"RobotUnknownParameterName",
       {{"r.yaml", "links:\n  - {theta: 0, alpha: 0, a: 0, d: 0, parameters: [gamma]}\n"}},
       "sample --robot r.yaml --out c.csv", 2, {"unknown parameter 'gamma'"}},
      {"RobotMissingValue", {{"r.yaml", "links:\n  - {theta: 0, alpha: 0, a: 0, parameters: [a]}\n"}},
       "sample --robot r.yaml --out c.csv", 2, {"key 'links[0].d'", "missing value"}},
      {"RobotTextForANumber",
       {{"r.yaml", "links:\n  - {theta: 0, alpha: 0, a: abc, d: 0, parameters: [a]}\n"}},
       "sample --robot r.yaml --out c.csv", 2, {"key 'links[0].a'", "got 'abc'"}},
      {"RobotNotAMapping", {{"r.yaml", "- a\n- b\n"}}, "sample --robot r.yaml --out c.csv", 2,
       {"r.yaml", "expected a mapping"}},
      {"RobotWithoutParameters",
       {{"r.yaml", "links:\n  - {theta: 0, alpha: 0, a: 0.5, d: 0, parameters: []}\n"
                   "plane: {normal: [1, 0, 0], offset: -1}\n"},
        {"m.csv", "q1,h\n0,0.5\n"}},
       "identify --robot r.yaml --data m.csv", 2, {"nothing left to estimate"}},
      // ---- Study files -------------------------------------------------------------------
      {"StudySectionGivenAsNothing", {{"s.yaml", "{study}noise:\n"}},
       "run s.yaml --out run", 2, {"s.yaml:5 key 'noise'", "expected a mapping", "got nothing"}},
      {"StudySectionGivenAsScalar", {{"s.yaml", "{study}noise: 5\n"}}, "run s.yaml --out run",
       2, {"s.yaml:5 key 'noise'", "expected a mapping"}},
      {"StudyNameDotDot", {{"s.yaml", "name: ..\nseed: 1\ntrials: 3\n"}}, "run s.yaml", 2,
       {"s.yaml:1 key 'name'", "plain name"}},
      {"StudyNameWithSlash", {{"s.yaml", "name: a/b\nseed: 1\ntrials: 3\n"}}, "run s.yaml", 2,
       {"key 'name'", "plain name"}},
      {"StudyInvalidUtf8", {{"s.yaml", "{study}description: \"caf\xe9\"\n"}},
       "run s.yaml --out run", 2, {"s.yaml:5 key 'description'", "not valid UTF-8"}},
      {"StudyComplexKey", {{"s.yaml", "{study}? [a, b]\n: 1\n"}}, "run s.yaml --out run", 2,
       {"s.yaml:5", "expected a plain key"}},
      {"StudyRepeatedKey", {{"s.yaml", "{study}seed: 2\n"}}, "run s.yaml --out run", 2,
       {"s.yaml:5 key 'seed'", "repeated key (first at line 2)"}},
      {"StudyAliasBomb",
       {{"s.yaml", "{study}a: &a [x, x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, "
                   "*a, *a, *a, *a]\nc: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b, *b]\nd: &d [*c, "
                   "*c, *c, *c, *c, *c, *c, *c, *c, *c]\ne: &e [*d, *d, *d, *d, *d, *d, *d, *d, "
                   "*d, *d]\nf: [*e, *e, *e, *e, *e, *e, *e, *e, *e, *e]\n"}},
       "run s.yaml --out run", 2, {"s.yaml", "more than 100000 values"}},
      {"StudySamplesHuge", {{"s.yaml", "{study}selection: {samples: 1e9}\n"}},
       "run s.yaml --out run", 2, {"key 'selection.samples'", "from 1 to 1000000"}},
      {"StudyPoolHuge", {{"s.yaml", "{study}pool: {size: 1e9}\n"}}, "run s.yaml --out run", 2,
       {"key 'pool.size'", "from 1 to 100000"}},
      {"StudyValidationOverflowsInt", {{"s.yaml", "{study}validation: {size: 357913942}\n"}},
       "run s.yaml --out run", 2, {"key 'validation.size'", "from 1 to 100000"}},
      {"StudyRepetitionsHuge", {{"s.yaml", "{study}noise: {repetitions: 2e9}\n"}},
       "run s.yaml --out run", 2, {"key 'noise.repetitions'"}},
      {"StudyTooManyCells",
       {{"s.yaml", "{study}sweep:\n  axes:\n"
                   "    - {key: noise.sigma_mm, values: [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]}\n"
                   "    - {key: noise.repetitions, values: [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]}\n"
                   "    - {key: truth.scale, values: [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]}\n"
                   "    - {key: selection.count, values: [26, 27, 28, 29, 30, 31, 32, 33, 34, "
                   "35]}\n"
                   "    - {key: validation.size, values: [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]}\n"
                   "    - {key: pool.size, values: [91, 92, 93, 94, 95, 96, 97, 98, 99, 100]}\n"}},
       "run s.yaml --out run", 2, {"key 'sweep.axes'", "at most 100000"}},
      {"StudyMaxIterationsHuge", {{"s.yaml", "{study}identification: {max_iterations: 1e8}\n"}},
       "run s.yaml --out run", 2, {"key 'identification.max_iterations'"}},
      {"StudyMissingSeed", {{"s.yaml", "name: s\ntrials: 3\n"}}, "run s.yaml --out run", 2,
       {"s.yaml:1 key 'seed'", "missing (required)"}},
      {"StudyNegativeNoise", {{"s.yaml", "{study}noise: {sigma_mm: -1}\n"}},
       "run s.yaml --out run", 2, {"key 'noise.sigma_mm'", ">= 0"}},
      {"StudyUnknownSection", {{"s.yaml", "{study}noize: {sigma_mm: 1}\n"}},
       "run s.yaml --out run", 2, {"s.yaml:5 key 'noize'", "unknown key"}},
      {"StudyIsADirectory", {}, "run {dir} --out run", 2, {"is a directory"}, "true"},
      {"StudyMissingRobotFile", {{"s.yaml", "name: s\nseed: 1\ntrials: 3\nrobot: /no/r.yaml\n"}},
       "run s.yaml --out run", 2, {"key 'robot'", "cannot open robot file"}},
      {"StudyRobotIsADirectory", {{"s.yaml", "name: s\nseed: 1\ntrials: 3\nrobot: {dir}\n"}},
       "run s.yaml --out run", 2, {"key 'robot'", "cannot open robot file"}},
      {"StudyUnknownSolver", {{"s.yaml", "{study}identification: {solver: gauss}\n"}},
       "run s.yaml --out run", 2, {"unknown solver 'gauss'; expected lm or ceres"}},
      {"StudyCountAbovePool", {{"s.yaml", "{study}pool: {size: 40}\nselection: {count: 41}\n"}},
       "run s.yaml --out run", 2, {"key 'selection.count'", "pool of 40"}},
      {"StudyNoTrials", {{"s.yaml", "name: s\nseed: 1\ntrials: 0\n"}}, "run s.yaml --out run",
       2, {"key 'trials'", "from 1"}},
      {"StudyPlaneTiltAbove180", {{"s.yaml", "{study}plane: {tilt_deg: 200}\n"}},
       "run s.yaml --out run", 2, {"key 'plane.tilt_deg'", "[0, 180]"}},
      {"StudySweepOfAnUnknownKey",
       {{"s.yaml", "{study}sweep:\n  axes:\n    - {key: noise.sigma, values: [1]}\n"}},
       "run s.yaml --out run", 2, {"key 'sweep.axes[0].key'", "not a study setting"}},
      {"StudyNotAMapping", {{"s.yaml", "- a\n- b\n"}}, "run s.yaml --out run", 2,
       {"s.yaml", "expected a mapping"}},
      {"StudyPlanToo", {{"s.yaml", "{study}pool: {size: 1e9}\n"}}, "plan s.yaml", 2,
       {"key 'pool.size'"}},
      // ---- Options -----------------------------------------------------------------------
      {"RunNegativeThreads", {}, "run quick --threads -1 --out run", 2,
       {"--threads", "0 (all cores) to 4096"}},
      {"RunHundredThousandThreads", {}, "run quick --threads 100000 --out run", 2,
       {"--threads", "to 4096"}},
      {"RunShardOutOfRange", {}, "run quick --shard 3/2 --out run", 2,
       {"--shard", "1 <= i <= N"}},
      {"RunEmptyOut", {}, "run quick --out ''", 2, {"--out", "empty name"}},
      {"RunOutIsAFile", {{"f.txt", "x"}}, "run quick --out f.txt", 2, {"--out", "is a file"}},
      {"RunOutUnderAFile", {{"f.txt", "x"}}, "run quick --out f.txt/run", 2,
       {"--out", "cannot create the run directory"}},
      {"RunUnknownSchedule", {}, "run quick --schedule fifo --out run", 2,
       {"--schedule", "static or dynamic"}},
      {"RunNegativeMaxTrials", {}, "run quick --max-trials -5 --out run", 2,
       {"--max-trials", "positive number"}},
      {"SampleOutIsADirectory", {}, "sample --out {dir}", 2, {"--out", "is a directory"}},
      {"SampleOutInAMissingFolder", {}, "sample --out no/such/c.csv", 2,
       {"--out", "does not exist"}},
      {"SampleEmptyOut", {}, "sample --out ''", 2, {"--out", "empty string"}},
      {"SampleCountHuge", {}, "sample --count 100000000 --out c.csv", 2,
       {"--count", "1 to 1,000,000"}},
      {"SampleCountZero", {}, "sample --count 0 --out c.csv", 2, {"--count"}},
      {"SampleNegativeSingularValue", {}, "sample --min-singular-value -1 --out c.csv", 2,
       {"--min-singular-value", "finite value >= 0"}},
      {"SimulateRepetitionsHuge", {{"c.csv", kConfigs}},
       "simulate --configs c.csv --repetitions 2000000000 --out m.csv", 2,
       {"--repetitions", "1 to 1,000,000"}},
      {"SimulateNegativeSigma", {{"c.csv", kConfigs}},
       "simulate --configs c.csv --sigma-mm -0.1 --out m.csv", 2, {"--sigma-mm"}},
      {"DesignNegativeBaseline", {}, "design --generate 40 --select 30 --baseline -1", 2,
       {"--baseline", "1 to 1,000,000"}},
      {"DesignZeroExpectedAngle", {},
       "design --generate 40 --select 30 --scaling expected --expected-angle-mrad 0", 2,
       {"--expected-angle-mrad", "finite value > 0"}},
      {"DesignNanExpectedLength", {},
       "design --generate 40 --select 30 --scaling expected --expected-length-mm nan", 2,
       {"--expected-length-mm", "finite value > 0"}},
      {"DesignGenerateHuge", {}, "design --generate 10000000 --select 30", 2,
       {"--generate", "1 to 100,000"}},
      {"PaperZeroSamples", {}, "paper --samples 0 --case1-selection sampled", 2,
       {"--samples", "at least 1"}},
      {"IdentifyInfiniteLossScale", {{"m.csv", "q1,q2,q3,q4,q5,q6,h\n0,0,0,0,0,0,1\n"}},
       "identify --data m.csv --solver ceres --loss huber --loss-scale-mm inf", 2,
       {"--loss-scale-mm", "finite scale > 0"}},
      {"IdentifyZeroLossScale", {{"m.csv", "q1,q2,q3,q4,q5,q6,h\n0,0,0,0,0,0,1\n"}},
       "identify --data m.csv --loss-scale-mm 0", 2, {"--loss-scale-mm"}},
      {"PlaneInfinite", {{"c.csv", kConfigs}}, "kinematics --configs c.csv --plane inf,0,1,0",
       2, {"--plane", "'inf' is not a number"}},
      {"NegativeSeed", {}, "sample --seed -1 --out c.csv", 2, {"--seed", "non-negative"}},
      {"UnknownFormat", {{"c.csv", kConfigs}}, "kinematics --configs c.csv --format xml", 2,
       {"--format", "text or json"}},
      {"UnknownModel", {{"c.csv", kConfigs}}, "kinematics --configs c.csv --model measured", 2,
       {"--model", "nominal or true"}},
      // ---- Run directories ---------------------------------------------------------------
      {"StatusOfAnEmptyFolder", {}, "status {dir}", 2, {"not an lrcal run directory"}},
      {"StatusOfAMissingFolder", {}, "status {dir}/none", 2, {"not an lrcal run directory"}},
      {"StatusManifestNotJson", {{"manifest.json", "{"}, {"trials.sqlite", ""}}, "status {dir}",
       2, {"manifest.json", "not valid JSON"}},
      {"StatusManifestWithoutStudy", {{"manifest.json", "{}"}, {"trials.sqlite", ""}},
       "status {dir}", 2, {"manifest.json key 'study'", "damaged"}},
      {"StatusManifestWithoutCells",
       {{"manifest.json", "{\"study\": {\"name\": \"s\", \"seed\": 1, \"trials\": 3, "
                          "\"base\": {}}, \"shard\": {\"index\": 1, \"count\": 1}, "
                          "\"sessions\": []}"},
        {"trials.sqlite", ""}},
       "status {dir}", 2, {"key 'study.cells'"}},
      {"AggregateManifestWithoutShard",
       {{"manifest.json", "{\"study\": {\"name\": \"s\", \"seed\": 1, \"trials\": 3, "
                          "\"base\": {}, \"cells\": []}, \"sessions\": []}"},
        {"trials.sqlite", ""}},
       "aggregate {dir}", 2, {"key 'shard'"}},
      {"ReportOfAnEmptyFolder", {}, "report {dir}", 2, {"manifest.json is missing"}},
      {"MergeIntoItself", {}, "merge a --out a", 2, {"--out", "one of the directories to merge"},
       "{lrcal} run quick --out a --quiet > /dev/null 2>&1"},
      {"MergeOfARunningShard", {}, "merge a --out b", 2,
       {"cannot merge it now", "another lrcal process"},
       "{lrcal} run quick --out a --quiet > /dev/null 2>&1; (flock a/lock sleep 5 > /dev/null 2>&1 &) ; sleep 0.3"},
      {"ResumeWithAnotherSeed", {{"s.yaml", "name: quick\nseed: 99\ntrials: 5\n"}},
       "run s.yaml --out a", 2, {"different study", "seed"},
       "{lrcal} run quick --out a --quiet > /dev/null 2>&1"},
  };
  return cases;
}

INSTANTIATE_TEST_SUITE_P(Cases, BadInputTest, ::testing::ValuesIn(Cases()),
                         [](const ::testing::TestParamInfo<BadInput>& info) {
                           return info.param.name;
                         });

TEST(BadInputTable, HasAtLeastEightyCasesOfBadInput) {
  int bad = 0;
  for (const auto& c : Cases()) bad += c.exit_code == 2;
  EXPECT_GE(bad, 80);
}

}  // namespace
}  // namespace lrcal
