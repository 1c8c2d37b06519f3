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
#include "study/trial_pipeline.h"

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

void PrintRunSummary(const RunResult& r, const RunOptions& options, int ranks) {
  if (r.ranks_computed == 0 && r.done_before >= r.total) {
    std::cerr << "lrcal run: nothing to compute: all " << r.total
              << " trials of this run were already recorded\n";
    return;
  }
  std::cerr << "lrcal run: " << r.ranks_computed << " trials computed in " << Fixed(r.seconds, 1)
            << " s (of " << r.total << " in this run; " << r.done_before
            << " were already recorded";
  if (r.computed > 0)
    std::cerr << "; " << Fixed(1e6 * r.trial_seconds / r.computed, 1) << " µs of compute per trial"
              << (ranks > 1 ? " on rank 0" : "");
  std::cerr << ")\n";
  if (r.computed == 0) return;
  const int threads = options.threads > 0
                          ? options.threads
                          : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  // The runner's overhead is only measurable when the trials take a while: on a run of a few
  // milliseconds thread start-up dominates and a percentage would mislead.
  const std::string overhead =
      r.run_seconds >= 1.0
          ? "runner overhead " + Fixed(100 * (r.run_seconds * threads / r.trial_seconds - 1), 1) +
                " % over the trials' own time"
          : "too short to measure the runner's overhead";
  std::cerr << "lrcal run: wall time: prepare " << Fixed(r.prepare_seconds, 3) << " s, trials "
            << Fixed(r.run_seconds, 3) << " s (" << threads << " threads"
            << (ranks > 1 ? " on rank 0 of " + std::to_string(ranks) : std::string()) << "; "
            << overhead << "), tables " << Fixed(r.tables_seconds, 3) << " s; peak memory "
            << r.peak_rss_kb_trials / 1024 << " MiB after the trials, " << r.peak_rss_kb / 1024
            << " MiB with the tables\n";
}

// Shards of one study: which array tasks to resubmit, or how to merge.
void PrintShardAdvice(const std::vector<std::string>& dirs,
                      const std::vector<RunStatusInfo>& infos) {
  std::string unfinished;
  std::set<int> present;
  for (const auto& i : infos) {
    present.insert(i.shard_index);
    if (!i.complete) unfinished += (unfinished.empty() ? "" : ",") + std::to_string(i.shard_index);
  }
  const int n = infos.front().shard_count;
  for (int i = 1; i <= n; ++i)
    if (!present.count(i)) unfinished += (unfinished.empty() ? "" : ",") + std::to_string(i);
  if (unfinished.empty()) {
    std::cout << "all " << n << " shards complete: lrcal merge ";
    for (const auto& d : dirs) std::cout << d << " ";
    std::cout << "--out DIR\n";
    return;
  }
  std::cout << "unfinished or missing shards: " << unfinished << "\n"
            << "resubmit: sbatch --array=" << unfinished << " studies/slurm/lrcal_array.sbatch "
            << infos.front().study_file << " " << n << "\n";
}

}  // namespace

int RunCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal run options");
  o.add_options()("study", po::value<std::string>(), "study file (default: studies/paper.yaml)")(
      "out", po::value<std::string>(), "run directory (default: output/<study name>)")(
      "shard", po::value<std::string>(), "run only shard i/N of the trials (batch schedulers)")(
      "schedule", po::value<std::string>()->default_value("static"),
      "MPI only: static (every P-th trial per rank) or dynamic (chunks from rank 0)")(
      "quiet", po::bool_switch(), "no progress output");
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
  PrintRunSummary(r, options, ranks);
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
  const int threads = vm["threads"].as<int>() > 0
                          ? vm["threads"].as<int>()
                          : std::max(1u, std::thread::hardware_concurrency());
  Table t({"cell", "id", "trials", "prepare (s)", "µs/trial (measured)", "estimate (s)"},
          "Plan of study '" + study.name + "' (dry run: each cell prepared, a few trials timed)");
  Json j = Json::array();
  double total_seconds = 0;
  for (const Cell& cell : study.cells) {
    const auto t0 = std::chrono::steady_clock::now();
    auto ctx = PrepareCell(study, cell);
    const auto t1 = std::chrono::steady_clock::now();
    TrialWorkspace ws;
    const int probe = static_cast<int>(std::min<long long>(study.trials, 20));
    for (int k = 0; k < probe; ++k) RunTrial(*ctx, k, &ws);
    const auto t2 = std::chrono::steady_clock::now();
    const double prep = std::chrono::duration<double>(t1 - t0).count();
    const double per = std::chrono::duration<double>(t2 - t1).count() / probe;
    const double est = prep + per * study.trials / threads;
    total_seconds += est;
    t.AddRow({cell.label, cell.id, std::to_string(study.trials), Fixed(prep, 3),
              Fixed(per * 1e6, 1), Fixed(est, 1)});
    j.push_back({{"label", cell.label},
                 {"id", cell.id},
                 {"trials", study.trials},
                 {"prepare_seconds", prep},
                 {"seconds_per_trial", per},
                 {"estimate_seconds", est},
                 {"settings", cell.settings}});
  }
  if (vm["format"].as<std::string>() == "json") {
    std::cout << Json{{"study", study.name},
                      {"cells", j},
                      {"threads", threads},
                      {"total_trials", study.total_trials()},
                      {"estimate_seconds", total_seconds}}
                     .dump(2)
              << "\n";
  } else {
    std::cout << t.ToText() << "total: " << study.cells.size() << " cells, " << study.total_trials()
              << " trials, about " << Fixed(total_seconds, total_seconds < 10 ? 1 : 0) << " s on "
              << threads << " threads\n";
  }
  return 0;
}

int StatusCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal status options");
  o.add_options()("dirs", po::value<std::vector<std::string>>()->multitoken()->required(),
                  "run directories (several: the shards of one study)");
  po::positional_options_description pos;
  pos.add("dirs", -1);
  po::variables_map vm;
  if (!Parse("status", "RUN_DIR...", o, args, &vm, &pos)) return 0;
  const auto dirs = vm["dirs"].as<std::vector<std::string>>();
  std::vector<RunStatusInfo> infos;
  for (const std::string& d : dirs) {
    infos.push_back(GetRunStatus(d));
    std::cout << infos.back().text;
  }
  if (infos.size() > 1 && infos.front().shard_count > 1) PrintShardAdvice(dirs, infos);
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
  const bool complete = MergeRuns(dirs, out);
  if (complete) {
    std::cout << RunStatus(out) << "tables: " << out << "/tables/summary.md\n";
    return 0;
  }
  // Not every trial is in the shards: say which shards to finish, write no tables.
  const RunStatusInfo merged = GetRunStatus(out);
  std::cout << merged.text.substr(0, merged.text.find("last session"));
  std::vector<RunStatusInfo> infos;
  for (const auto& d : dirs) infos.push_back(GetRunStatus(d));
  PrintShardAdvice(dirs, infos);
  std::cout << "tables not written: the shards do not hold every trial yet; finish them and run "
               "lrcal merge again\n";
  return 1;
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
