// lrcal trial: replay one recorded trial of a run with everything in it, and check it against the
// stored record bit for bit.
#include "cli_common.h"
#include "lrcal/study/trial_replay.h"

namespace lrcal::cli {

int TrialCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal trial options");
  o.add_options()("dir", po::value<std::string>()->required(), "run directory")(
      "cell", po::value<std::string>()->required(), "cell id or label")(
      "trial", po::value<long long>()->required(), "trial index (0-based)")(
      "format", po::value<std::string>()->default_value("text"), "text or json");
  po::positional_options_description pos;
  pos.add("dir", 1);
  po::variables_map vm;
  if (!Parse("trial", "RUN_DIR --cell ID --trial N [--format json]", o, args, &vm, &pos)) return 0;
  const Format format = ResolveFormat(vm);
  const TrialReplay t = ReplayTrial(vm["dir"].as<std::string>(), vm["cell"].as<std::string>(),
                                    vm["trial"].as<long long>());
  if (format == Format::kJson) {
    std::cout << t.ToJson().dump(2) << "\n";
  } else {
    std::cout << t.ToText();
  }
  // A recorded trial that cannot be reproduced is a failure a script must see.
  return t.stored && !t.identical() ? 1 : 0;
}

}  // namespace lrcal::cli
