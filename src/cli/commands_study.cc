// The study subcommands: run, plan, status, merge, aggregate.
#include <chrono>
#include <filesystem>
#include <set>
#include <thread>

#include "cli_common.h"
#include "lrcal/core/text_table.h"
#include "lrcal/report/run_tables.h"
#include "lrcal/study/collective.h"
#include "lrcal/study/run_directory.h"
#include "lrcal/study/runner.h"
#include "lrcal/study/study.h"
#include "lrcal/study/study_plan.h"

namespace lrcal::cli {

namespace {

constexpr const char* kDefaultStudy = "paper";

Study LoadStudyArg(const po::variables_map& vm) {
  const std::string arg = vm.count("study") ? vm["study"].as<std::string>() : kDefaultStudy;
  return LoadStudy(ResolveStudyPath(arg));
}

std::string DefaultOut(const Study& study) { return "output/" + study.name; }

RunOptions ResolveRunOptions(const po::variables_map& vm, const Study& study) {
  RunOptions options;
  options.out_dir = vm.count("out") ? vm["out"].as<std::string>() : DefaultOut(study);
  ReadSettingOptions(vm, RunOptions::Settings(), &options);
  if (vm.count("shard"))
    ParseShard(vm["shard"].as<std::string>(), &options.shard_index, &options.shard_count);
  options.progress = !vm["quiet"].as<bool>();
  const std::string schedule = vm["schedule"].as<std::string>();
  if (schedule != "static" && schedule != "dynamic")
    throw InputError("--schedule", "expected static or dynamic, got '" + schedule + "'");
  options.dynamic_schedule = schedule == "dynamic";
  options.Validate();
  return options;
}

// The MPI world when started by mpirun (refused with the way out if built without MPI).
std::unique_ptr<Collective> MpiWorldIfLaunched() {
  if (!LaunchedUnderMpi()) return nullptr;
  if (!BuiltWithMpi())
    throw InputError("mpirun",
                     "this lrcal was built without MPI (CMake found no MPI when it "
                     "was configured): install OpenMPI (libopenmpi-dev) and rebuild, "
                     "or run without mpirun (threads: --threads N; several machines: "
                     "--shard i/N and lrcal merge)");
  return MpiWorld(nullptr, nullptr);
}

}  // namespace

int RunCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal run options");
  o.add_options()("study", po::value<std::string>(), "study file (default: studies/paper.yaml)")(
      "out", po::value<std::string>(), "run directory (default: output/<study name>)")(
      "shard", po::value<std::string>(), "run only shard i/N of the trials (batch schedulers)")(
      "schedule", po::value<std::string>()->default_value("static"),
      "MPI only: static (blocks of trials dealt to the ranks in turn; each rank prepares "
      "only its blocks' cells) or dynamic (chunks from rank 0)")("quiet", po::bool_switch(),
                                                                 "no progress output");
  AddSettingOptions(o, RunOptions::Settings(), {"threads", "max_trials"});
  po::positional_options_description pos;
  pos.add("study", 1);
  po::variables_map vm;
  if (!Parse("run", "[STUDY.yaml] [--out DIR] [--threads N] [--shard i/N]", o, args, &vm, &pos))
    return 0;
  const Study study = LoadStudyArg(vm);
  const RunOptions options = ResolveRunOptions(vm, study);
  // Under mpirun: every rank runs this command; trials are dealt to the ranks.
  std::unique_ptr<Collective> world = MpiWorldIfLaunched();
  const int rank = world ? world->rank() : 0;
  const int ranks = world ? world->size() : 1;
  InstallStopHandlers();
  if (rank == 0)
    std::cerr << "lrcal run: study '" << study.name << "', " << study.cells.size() << " cells × "
              << study.trials << " trials → " << options.out_dir
              << (ranks > 1 ? " (" + std::to_string(ranks) + " MPI ranks)" : std::string()) << "\n";
  const RunResult r = RunStudyAndWriteTables(study, options, world.get());
  if (rank != 0) return r.interrupted && !r.reached_max_trials ? 130 : 0;
  std::cerr << RunSummaryText(r, options, ranks);
  if (r.tables_written) {
    std::cout << "tables: " << options.out_dir << "/tables/summary.md (also .csv, .json, .tex)\n";
  } else if (r.reached_max_trials) {
    std::cout << "stopped after " << r.ranks_computed
              << " new trials (--max-trials): " << r.done_before + r.ranks_computed << "/"
              << r.total << " trials recorded; run the same command again to continue\n";
  } else if (r.interrupted && r.total == 0) {
    std::cout << "interrupted while the cells were prepared; nothing was written\n";
    return 130;
  } else if (r.interrupted) {
    std::cout << "interrupted: " << r.done_before + r.computed << "/" << r.total
              << " trials recorded; run the same command again to continue\n";
    return 130;
  } else {
    std::cout << "shard done; combine the shards with: lrcal merge DIR... --out DIR\n";
  }
  return 0;
}

int PlanCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal plan options");
  o.add_options()("study", po::value<std::string>(), "study file (default: studies/paper.yaml)")(
      "threads", po::value<int>()->default_value(0), "threads the run would use (0: all cores)")(
      "format", po::value<std::string>()->default_value("text"), "text or json");
  po::positional_options_description pos;
  pos.add("study", 1);
  po::variables_map vm;
  if (!Parse("plan", "[STUDY.yaml]", o, args, &vm, &pos)) return 0;
  const Study study = LoadStudyArg(vm);
  const StudyPlan plan = PlanStudy(study, vm["threads"].as<int>());
  if (ResolveFormat(vm) == Format::kJson) {
    std::cout << plan.ToJson().dump(2) << "\n";
  } else {
    std::cout << plan.ToText();
  }
  return 0;
}

int StatusCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal status options");
  o.add_options()("dirs", po::value<std::vector<std::string>>()->multitoken()->required(),
                  "run directories (several: the shards of one study)")(
      "format", po::value<std::string>()->default_value("text"),
      "text or json (one object per directory, in a list when several are given)");
  po::positional_options_description pos;
  pos.add("dirs", -1);
  po::variables_map vm;
  if (!Parse("status", "RUN_DIR... [--format json]", o, args, &vm, &pos)) return 0;
  const Format format = ResolveFormat(vm);
  const auto dirs = vm["dirs"].as<std::vector<std::string>>();
  std::vector<RunStatusInfo> infos;
  Json list = Json::array();
  for (const std::string& d : dirs) {
    infos.push_back(GetRunStatus(d));
    if (format == Format::kText) std::cout << infos.back().text;
    list.push_back(Json::parse(infos.back().json.dump()));
  }
  if (format == Format::kJson) {
    std::cout << (list.size() == 1 ? list[0] : list).dump(2) << "\n";
    return 0;
  }
  if (infos.size() > 1 && infos.front().shard_count > 1) std::cout << ShardAdvice(dirs, infos);
  return 0;
}

int MergeCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal merge options");
  o.add_options()("dirs", po::value<std::vector<std::string>>()->multitoken()->required(),
                  "shard run directories")("out", po::value<std::string>()->required(),
                                           "merged run directory");
  po::positional_options_description pos;
  pos.add("dirs", -1);
  po::variables_map vm;
  if (!Parse("merge", "DIR... --out DIR", o, args, &vm, &pos)) return 0;
  const auto& dirs = vm["dirs"].as<std::vector<std::string>>();
  const std::string out = vm["out"].as<std::string>();
  const MergeOutcome merged = MergeRunsAndReport(dirs, out);
  std::cout << merged.text;
  return merged.complete ? 0 : 1;
}

int AggregateCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal aggregate options");
  o.add_options()("dir", po::value<std::string>()->required(), "run directory");
  po::positional_options_description pos;
  pos.add("dir", 1);
  po::variables_map vm;
  if (!Parse("aggregate", "RUN_DIR", o, args, &vm, &pos)) return 0;
  WriteRunTables(vm["dir"].as<std::string>());
  std::cout << "tables: " << vm["dir"].as<std::string>() << "/tables/summary.md\n";
  return 0;
}

}  // namespace lrcal::cli
