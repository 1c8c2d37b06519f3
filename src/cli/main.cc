// lrcal: kinematic calibration of robot arms with a laser ranger, and Monte-Carlo studies of it.
// A thin layer over the library: each subcommand parses its options and calls lrcal/.
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <iostream>

#include "cli_common.h"
#include "lrcal/build_info.h"
#include "lrcal/core/machine.h"

namespace lrcal::cli {

const std::vector<Command>& Commands() {
  static const std::vector<Command> commands = {
      {"run", "run (or resume) a Monte-Carlo study: lrcal run [STUDY.yaml] [--out DIR]",
       RunCommand},
      {"plan", "dry run: cells, trials and an estimated run time of a study", PlanCommand},
      {"plan-accuracy",
       "the cheapest campaign (configurations x readings) that meets an accuracy target",
       PlanAccuracyCommand},
      {"status", "done / remaining trials per cell of a run directory", StatusCommand},
      {"merge", "combine shard run directories into one run", MergeCommand},
      {"trial", "replay one recorded trial in detail and check it against its record",
       TrialCommand},
      {"aggregate", "rewrite the tables of a run directory from its trial store", AggregateCommand},
      {"report", "figures (PNG, SVG) and a self-contained report.html of a run, partial or not",
       ReportCommand},
      {"design", "choose k of N configurations by an observability criterion, against random",
       DesignCommand},
      {"paper", "the paper's case 1 and case 2, one realisation, beside its published tables",
       PaperCommand},
      {"kinematics", "tool pose, beam, laser distance (and Jacobian row) per configuration",
       KinematicsCommand},
      {"sample", "draw measurement or validation configurations for a robot and plane",
       SampleCommand},
      {"simulate", "noisy laser readings of the true robot at given configurations",
       SimulateCommand},
      {"identify", "identify the parameters from measured (or simulated) readings",
       IdentifyCommand},
      {"identifiability", "rank, singular values and dependencies of a parameter set",
       IdentifiabilityCommand},
      {"accuracy", "predicted pose accuracy of a calibrated robot file at given poses",
       AccuracyCommand},
      {"export", "write a robot (a calibrated one) as URDF, a D-H table or a robot YAML file",
       ExportCommand},
      {"compensate", "joint commands that reach the nominal plan's tool poses on a calibrated arm",
       CompensateCommand},
  };
  return commands;
}

}  // namespace lrcal::cli

namespace {

// Under mpirun every rank meets the same input errors: rank 0 alone reports them.
bool OtherMpiRank() {
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"})
    if (const char* v = std::getenv(name)) return std::atoi(v) != 0;
  return false;
}

void PrintUsage(std::ostream& out) {
  out << "lrcal " << LRCAL_VERSION << " — laser-ranger calibration of robot arms\n\n"
      << "usage: lrcal COMMAND [options]   (lrcal COMMAND --help for its options)\n\ncommands:\n";
  for (const auto& c : lrcal::cli::Commands())
    out << "  " << c.name << std::string(18 - c.name.size(), ' ') << c.summary << "\n";
}

// After an input error: a note when the command ran on --robot's default because none was given.
std::string DefaultRobotNote(const std::string& command) {
  if (!lrcal::cli::RobotWasDefaulted()) return "";
  return "lrcal " + command +
         ": note: no --robot was given, so this used the paper's arm (the default); give --robot "
         "FILE (YAML or URDF) for another arm\n";
}

}  // namespace

int main(int argc, char** argv) {
  // A file-size limit (ulimit -f) would kill lrcal with SIGXFSZ mid-write; ignored, the write
  // fails with EFBIG instead and is reported like a full disk (exit 5, nothing computed lost).
  std::signal(SIGXFSZ, SIG_IGN);
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") ||
      !std::strcmp(argv[1], "help")) {
    PrintUsage(std::cout);
    return argc < 2 ? 2 : 0;
  }
  if (!std::strcmp(argv[1], "--version")) {
    std::cout << "lrcal " << LRCAL_VERSION << " (" << LRCAL_GIT_COMMIT << ", " << LRCAL_COMPILER
              << "; kernels: " << lrcal::KernelVariant() << ")\n";
    return 0;
  }
  const std::string name = argv[1];
  std::vector<std::string> args(argv + 2, argv + argc);
  for (const auto& c : lrcal::cli::Commands()) {
    if (c.name != name) continue;
    try {
      return c.run(args);
    } catch (const lrcal::SettingError& e) {  // a library check: in the option's words
      if (!OtherMpiRank())
        std::cerr << "lrcal " << name
                  << ": error: " << e.Respelled(lrcal::Frontend::kCommandLine).what() << "\n"
                  << DefaultRobotNote(name);
      return 2;
    } catch (const lrcal::InputError& e) {
      if (!OtherMpiRank())
        std::cerr << "lrcal " << name << ": error: " << e.what() << "\n" << DefaultRobotNote(name);
      return 2;
    } catch (const lrcal::StorageError& e) {
      std::cerr << "lrcal " << name << ": could not write results: " << e.what() << "\n";
      return 5;
    } catch (const std::exception& e) {
      std::cerr << "lrcal " << name << ": failed: " << e.what() << "\n";
      return 1;
    }
  }
  std::cerr << "lrcal: unknown command '" << name << "'\n\n";
  PrintUsage(std::cerr);
  return 2;
}
