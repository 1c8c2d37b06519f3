// lrcal report RUN_DIR: tables and a one-realisation file from the run's records (C++), then the
// figures and report.html (python3 -m lrcal.report, which only reads what lrcal wrote).
#include <chrono>
#include <cstdlib>
#include <filesystem>

#include "cli_common.h"
#include "lrcal/core/data_dir.h"
#include "lrcal/core/text_table.h"
#include "lrcal/report/report_data.h"

namespace lrcal::cli {

int ReportCommand(const std::vector<std::string>& args) {
  po::options_description o("lrcal report options");
  o.add_options()("dir", po::value<std::string>()->required(), "run directory");
  po::positional_options_description pos;
  pos.add("dir", 1);
  po::variables_map vm;
  if (!Parse("report", "RUN_DIR", o, args, &vm, &pos)) return 0;
  const std::string dir = vm["dir"].as<std::string>();
  const auto t0 = std::chrono::steady_clock::now();
  const ReportData data = PrepareReportData(dir);
  int code = 0;
  try {
    code = RunReportModule({dir});
  } catch (...) {  // no interpreter: the snapshot goes all the same
    RemoveReportSnapshot(data);
    throw;
  }
  RemoveReportSnapshot(data);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (code != 0) {
    std::cerr << "lrcal report: python3 -m lrcal.report failed (exit " << code << ")\n";
    return code == 2 || code == 5 ? code : 1;
  }
  std::cout << "report: " << data.dir << "/report.html (" << data.done << "/" << data.expected
            << " trials" << (data.complete ? "" : ", PARTIAL run") << "; built in "
            << Fixed(seconds, 1) << " s)\n";
  if (!data.note.empty()) std::cout << data.note << "\n";
  return 0;
}

}  // namespace lrcal::cli
