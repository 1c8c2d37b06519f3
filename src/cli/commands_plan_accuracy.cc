// lrcal plan-accuracy: the cheapest campaign that meets an accuracy target
// (report/accuracy_plan.h).
#include "cli_common.h"
#include "lrcal/report/accuracy_plan.h"
#include "lrcal/study/study.h"

namespace lrcal::cli {

namespace {

AccuracyPlanOptions ReadOptions(const po::variables_map& vm) {
  AccuracyPlanOptions o;
  o.target = AccuracyTarget::Parse(vm["target"].as<std::string>());
  ReadSettingOptions(vm, AccuracyPlanOptions::NumericSettings(), &o);
  o.cost = CampaignCosts::Parse(vm["cost"].as<std::string>());
  if (vm.count("planes")) o.planes = vm["planes"].as<std::string>();
  if (vm.count("configurations")) o.configurations = vm["configurations"].as<std::string>();
  o.repetitions = vm["repetitions"].as<std::string>();
  if (vm.count("seed")) o.seed = ParseSeed(vm);
  if (vm.count("out")) o.out_dir = vm["out"].as<std::string>();
  o.threads = vm["threads"].as<int>();
  o.plan_on = ParsePlanBasis(vm["plan-on"].as<std::string>());
  return o;
}

}  // namespace

int PlanAccuracyCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal plan-accuracy options");
  o.add_options()("study", po::value<std::string>(),
                  "study file of the set-up (its base settings)")(
      "target", po::value<std::string>()->required(),
      "e.g. rms_pos=0.05mm: the quantile at --confidence of the largest per-axis RMS position "
      "error over the validation poses must not exceed it (also rms_ori, max_pos, max_ori)")(
      "configurations", po::value<std::string>(),
      "FIRST:LAST[:STEP] configurations to consider (default: parameters+1 to the pool size, "
      "step 5)")("repetitions",
                 po::value<std::string>()->default_value(AccuracyPlanOptions{}.repetitions),
                 "FIRST:LAST readings per configuration to consider")(
      "cost", po::value<std::string>()->default_value(CampaignCosts{}.ToString()),
      "time per configuration (move) and per reading, and per plane set up (plane=600s)")(
      "planes", po::value<std::string>(),
      "FIRST:LAST candidate planes a campaign may use, when the study's plane is a list of two "
      "or more (default: 1 to all; every subset of those sizes is considered)")(
      "seed", po::value<long long>(), "seed of the confirmation runs (default: the study's)")(
      "out", po::value<std::string>(),
      "folder for the confirmation study and run (default: output/STUDY-plan-HASH, named by the "
      "plan's settings)")("threads", po::value<int>()->default_value(0), "threads (0: all cores)")(
      "plan-on",
      po::value<std::string>()->default_value(
          NameOf(kPlanBasisNames, AccuracyPlanOptions{}.plan_on)),
      "total: the target holds for the first-order total (the reading noise's part plus the "
      "terms held at nominal at their tolerances); data: for the reading noise's part alone")(
      "format", po::value<std::string>()->default_value("text"), "text or json");
  AddSettingOptions(o, AccuracyPlanOptions::NumericSettings());
  po::positional_options_description pos;
  pos.add("study", 1);
  po::variables_map vm;
  if (!Parse("plan-accuracy", "[STUDY.yaml] --target rms_pos=0.05mm [options]", o, args, &vm, &pos))
    return 0;
  const Study study =
      LoadStudy(ResolveStudyPath(vm.count("study") ? vm["study"].as<std::string>() : "paper"));
  const AccuracyPlan plan = PlanAccuracy(study, ReadOptions(vm));
  if (ResolveFormat(vm) == Format::kJson) {
    std::cout << plan.ToJson().dump(2) << "\n";
  } else {
    std::cout << plan.ToText();
  }
  return 0;
}

}  // namespace lrcal::cli
