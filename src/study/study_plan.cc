#include "lrcal/study/study_plan.h"

#include <algorithm>
#include <chrono>
#include <thread>

#include "lrcal/core/text_table.h"
#include "study/preparation_memo.h"
#include "study/trial_pipeline.h"

namespace lrcal {

StudyPlan PlanStudy(const Study& study, int threads) {
  StudyPlan plan;
  plan.study = study.name;
  plan.threads =
      threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  plan.total_trials = study.total_trials();
  for (const Cell& cell : study.cells) {
    const auto t0 = std::chrono::steady_clock::now();
    auto ctx = PrepareCell(study, cell);
    const auto t1 = std::chrono::steady_clock::now();
    TrialWorkspace ws;
    const int probe = static_cast<int>(std::min<long long>(study.trials, 20));
    for (int k = 0; k < probe; ++k) RunTrial(*ctx, k, &ws);
    const auto t2 = std::chrono::steady_clock::now();
    CellPlan c;
    c.label = cell.label;
    c.id = cell.id;
    c.trials = study.trials;
    c.prepare_seconds = std::chrono::duration<double>(t1 - t0).count();
    c.seconds_per_trial = std::chrono::duration<double>(t2 - t1).count() / probe;
    c.estimate_seconds = c.prepare_seconds + c.seconds_per_trial * study.trials / plan.threads;
    c.settings = cell.settings;
    plan.estimate_seconds += c.estimate_seconds;
    plan.cells.push_back(std::move(c));
  }
  ClearPreparationMemos();  // as a run does once its cells are prepared
  return plan;
}

std::string StudyPlan::ToText() const {
  Table t({"cell", "id", "trials", "prepare (s)", "µs/trial (measured)", "estimate (s)"},
          "Plan of study '" + study + "' (dry run: each cell prepared, a few trials timed)");
  for (const CellPlan& c : cells)
    t.AddRow({c.label, c.id, std::to_string(c.trials), Fixed(c.prepare_seconds, 3),
              Fixed(c.seconds_per_trial * 1e6, 1), Fixed(c.estimate_seconds, 1)});
  return t.ToText() + "total: " + std::to_string(cells.size()) + " cells, " +
         std::to_string(total_trials) + " trials, about " +
         Fixed(estimate_seconds, estimate_seconds < 10 ? 1 : 0) + " s on " +
         std::to_string(threads) + " threads\n";
}

ResultJson StudyPlan::ToJson() const {
  ResultJson j = ResultJson::array();
  for (const CellPlan& c : cells)
    j.push_back({{"label", c.label},
                 {"id", c.id},
                 {"trials", c.trials},
                 {"prepare_seconds", c.prepare_seconds},
                 {"seconds_per_trial", c.seconds_per_trial},
                 {"estimate_seconds", c.estimate_seconds},
                 {"settings", ResultJson::parse(c.settings.dump())}});
  return {{"study", study},
          {"cells", j},
          {"threads", threads},
          {"total_trials", total_trials},
          {"estimate_seconds", estimate_seconds}};
}

}  // namespace lrcal
