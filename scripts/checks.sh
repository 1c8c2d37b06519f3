#!/usr/bin/env bash
# The code-health checks CI runs after the test suite (README "How it is built"):
#   format   clang-format on every C++ file (no differences allowed)
#   layers   no file includes a higher layer (scripts/check_layers.py)
#   tidy     clang-tidy's function-size and cognitive-complexity limits on src/ (.clang-tidy)
#   asan     every unit test built with AddressSanitizer + UndefinedBehaviorSanitizer
#   tsan     the Monte-Carlo runner and MPI tests (ctest label 'study') with ThreadSanitizer
#   docs     the API reference (Doxygen) builds without a warning
#   fuzz     libFuzzer on the CSV readers, robot files, URDFs, study files and the number parser
#            (ASan + UBSan, 10 s each in CI: scripts/fuzz.sh)
# Usage: bash scripts/checks.sh [format|layers|tidy|docs|asan|tsan|fuzz ...]  (default: all, in order)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_packages.sh clang-format clang-tidy python3
stages=("$@")
((${#stages[@]})) || stages=(format layers tidy docs asan tsan fuzz)

stage() { echo "== checks: $1 ($(date -u +%H:%M:%S))"; }
sanitizer_build() {  # dir, sanitizers, targets...
  local dir=$1 san=$2; shift 2
  # The library and the test binaries as unity builds (CMakeLists.txt, LRCAL_UNITY): about half
  # their compile time. Two sources of one target that define the same name in their anonymous
  # namespaces clash here: give such a helper one home (core/strings.h FileNumber, core/
  # settings.h kInf) or, in tests, a name of its own.
  # UBSan's pointer checks and its dynamic-type check (vptr) double the compile time of a test
  # file (one unity source of the measurement tests: 124 s of CPU with every check, 66 s
  # without these five, 57 s with ASan alone). They stay on the library and the program, the
  # code users run; the tests' own code keeps ASan and UBSan's other checks.
  local no_test=""
  [[ $san == *undefined* ]] && no_test=vptr,alignment,null,pointer-overflow,object-size
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" \
    -DLRCAL_SANITIZE="$san" -DLRCAL_TEST_NO_SANITIZE="$no_test" -DLRCAL_BUILD_BENCH=OFF \
    -DLRCAL_UNITY=ON > /dev/null
  cmake --build "$dir" -j2 --target "$@"
}

for s in "${stages[@]}"; do
  case "$s" in
    format)
      stage format
      git ls-files '*.cc' '*.h' | xargs clang-format --dry-run --Werror ;;
    layers)
      stage layers
      python3 scripts/check_layers.py ;;
    tidy)
      stage tidy
      cmake -S . -B build-tidy -DLRCAL_PCH=OFF -DCMAKE_EXPORT_COMPILE_COMMANDS=ON \
        -DLRCAL_BUILD_TESTS=OFF -DLRCAL_BUILD_BENCH=OFF > /dev/null
      ls src/*/*.cc | xargs -P2 -n1 clang-tidy -p build-tidy --quiet
      echo "clang-tidy: $(ls src/*/*.cc | wc -l) files within the limits" ;;
    docs)
      stage docs
      bash scripts/install_packages.sh doxygen
      doxygen docs/Doxyfile
      echo "doxygen: build/docs/html/index.html, no warnings" ;;
    asan)
      stage asan
      sanitizer_build build-asan address,undefined all
      export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
      # The end-to-end report tests spend their time in Python and Chromium and in whole studies
      # whose C++ (runner, trials, tables) the study and CLI tests already run under ASan; they
      # run in the Release suite (setup.sh test) and stay out of this stage, which they would
      # lengthen by several minutes for no code of their own. So do the statistical checks that
      # repeat one computation hundreds of times (a sensitivity study of single trials, forty
      # seeds of P95 intervals, the robust fit checks over many noise draws: 100 s of this
      # stage's CPU time): one pass of the same code runs under ASan in other tests. The two
      # kill -9 tests (40 s) check the store's durability across processes; the resumes they
      # make are the other MonteCarlo and Mpi tests' code, which run here.
      # The same holds for the Monte-Carlo confirmations of plan-accuracy (one of them,
      # ConfirmationStopsWhenPreciseEnough, runs here), the calibration report in Chromium, the
      # averaging efficiency over large counts and a sensitivity study's plan points (the other
      # sensitivity tests run here). Three more whole-run repeats (the sharded/resumed StopWhen
      # check, a study whose plane is never hit, the plan-accuracy exit codes: 35 s of CPU) run
      # in the Release suite only; their code runs here in the other StopWhen, study and
      # plan-accuracy tests.
      heavy='^(StopWhen\.StopsEveryCellWithThePrecisionStatedBitIdenticalAcrossThreadsShardsAndRestarts|Cases/BadStudyTest\.FailsBeforeAnythingRunsNamingLineAndKey/PlaneNeverHit.*|PlanAccuracy\.BadTargetsAndRangesAreExitTwo|Report\.(SensitivityStudyDrawsItsIndices|FiguresSayWhatTheyLeaveOut.*|QuickStudyReportRendersInHeadlessChromium|PartialRunIsReportedAsPartial|CalibrationReportRendersInHeadlessChromium)|PlanAccuracy\.(PlansOnTheTotalAndTheMonteCarloOfAHeldTermConfirmsIt|ChoosesAmongCandidatePlanes|ThePlanDoesNotDependOnWhereItIsWritten|EachPlanHasItsFolderAndAFolderKeepsItsSettings)|Averaging\.LargeCountsApproachTheAsymptoticEfficiency|SensitivityStudy\.PlanPointsAreCellsAndAnInputWithoutEffectHasZeroIndices|Storage\.MergeAndReportThatCannotWrite.*|SensitivityStudy\.ASingleTrialsFigureHasTheNoiseAsAnInput|Statistics\.P95IntervalsOfFortySeeds.*|Identification\.RobustFitCheckAgainstTheStatedNoise.*|MonteCarlo\.KilledProcessResumesToTheSameTables|Mpi\.KilledRankResumesWithAnotherRankCountToTheSameTables|ContactMeasurement\.StatedCovarianceHoldsOverManyRealisations|SocketMeasurement\.(StatedCovarianceHoldsWhereTheLinearisationCheckSaysSo|LinearisationCheckPredictsTheCovariancesOptimism))$'
      # OpenMPI's own allocations are not freed at exit: leak checks off for the MPI tests only.
      ASAN_OPTIONS=detect_leaks=1 ctest --test-dir build-asan -j2 --output-on-failure \
        -E "^Mpi\.|$heavy"
      ASAN_OPTIONS=detect_leaks=0 ctest --test-dir build-asan -j2 --output-on-failure -R '^Mpi\.' \
        -E "$heavy" ;;
    tsan)
      stage tsan
      sanitizer_build build-tsan thread lrcal_cli lrcal_study_tests
      # The statistics and sensitivity tests that run dozens of whole studies (4 of the 88, half
      # of this stage's time) repeat, on more trials, the threaded runner code that the
      # MonteCarlo, StopWhen and Mpi tests already run under TSan; they run in the Release and
      # ASan suites. So do the two kill -9 tests (100 s of this stage's CPU time): what they
      # check is the store's durability across processes, not threads; the threaded runs they
      # resume are the other MonteCarlo and Mpi tests' code. The environment study's prediction
      # test (6000 trials, 15 s here) checks a statistic of the trials, not their threading.
      repeats='^(Statistics\.(P95IntervalsOfFortySeeds.*|StreamingSummaryHasTheBitsOfSortingEveryValue)|SensitivityStudy\.(ASingleTrialsFigureHasTheNoiseAsAnInput|PlanPointsAreCells.*)|Mpi\.KilledRankResumesWithAnotherRankCountToTheSameTables|MonteCarlo\.KilledProcessResumesToTheSameTables|EnvironmentStudy\.TheFirstOrderPredictionFollowsTheTrialsAcrossTemperatures)$'
      TSAN_OPTIONS="suppressions=$PWD/tests/sanitizers/tsan.supp:halt_on_error=1" \
        ctest --test-dir build-tsan -j2 --output-on-failure -L study -E "$repeats" ;;
    fuzz)
      stage fuzz
      bash scripts/fuzz.sh "${LRCAL_FUZZ_SECONDS:-10}" ;;
    *) echo "unknown stage '$s' (format, layers, tidy, docs, asan, tsan, fuzz)" >&2; exit 2 ;;
  esac
done
echo "== checks: done ($(date -u +%H:%M:%S))"
