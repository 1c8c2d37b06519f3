#include "lrcal/report/calibration_report.h"

#include <algorithm>
#include <filesystem>

#include "lrcal/core/error.h"
#include "lrcal/core/json.h"
#include "lrcal/core/settings.h"
#include "lrcal/design/configuration_sampling.h"
#include "lrcal/identification/measured_accuracy.h"
#include "lrcal/io/calibration_record.h"
#include "lrcal/io/result_json.h"
#include "lrcal/io/urdf.h"

namespace lrcal {

namespace {

// The total accuracy map over the workspace, from the calibrated robot file just written: the
// computation of `lrcal accuracy --robot calibrated.yaml --workspace N --seed S`, poses drawn over
// the calibrated arm, so the report and the command agree to the bit.
void AddWorkspaceAccuracy(const CalibrationReportInputs& in, const RobotFile& calibrated,
                          ResultJson* j) {
  if (!calibrated.calibration || calibrated.calibration->covariance.size() == 0) return;
  const ConfigurationSet poses =
      WorkspacePoses(calibrated.robot, in.workspace_poses, in.workspace_seed);
  // A tracker's arm has no plane: the horizontal plane through the base only tags the poses.
  const PlaneSet planes = calibrated.planes ? *calibrated.planes
                          : in.model        ? in.model->nominal_planes()
                                            : PlaneSet(Plane{});
  (*j)["workspace_accuracy"] =
      PoseAccuracyJson(PredictCalibratedAccuracy(calibrated, planes, poses), poses);
}

}  // namespace

const SettingSpec& ReportFolderSetting() {
  static const SettingSpec spec{"identification",
                                "report",
                                "report",
                                "",
                                1,
                                "",
                                0,
                                0,
                                false,
                                false,
                                "",
                                "",
                                "folder of the calibration report"};
  return spec;
}

void WriteCalibrationReportData(const std::string& dir, const CalibrationReportInputs& in) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    throw SettingError(ReportFolderSetting(),
                       "cannot create the folder '" + dir + "': " + ec.message());
  const IdentificationSummary& s = *in.summary;
  ResultJson j = IdentificationJson(s);
  const int configurations = in.kind ? in.values->size() : in.data->size();
  j["data"] = {{"file", in.data_source.name}, {"configurations", configurations}};
  if (in.kind) {
    j["sensor"] = in.kind->name();
    j["values_per_configuration"] = in.kind->rows_per_configuration();
    j["n_values"] = in.values->y.size();
  }
  j["robot"] = in.rig->path;
  j["sigma_given"] = in.options.sigma > 0 ? ResultJson(in.options.sigma) : ResultJson();
  j["identifiability"] = IdentifiabilityJson(s.identifiability);
  if (s.IsSolutionUsable()) {
    const int folds = in.holdout > 0 ? in.holdout : std::min(5, configurations);
    if (folds >= 2)
      j["holdout"] =
          CrossValidationJson(in.kind ? CrossValidate(*in.kind, *in.values, folds, in.options)
                                      : CrossValidate(*in.model, *in.data, folds, in.options));
    if (in.kind)
      WriteTrackerCalibratedRobot(dir + "/calibrated.yaml", in.data_source, *in.rig, *in.kind,
                                  *in.values, s, in.options);
    else
      WriteCalibratedRobot(dir + "/calibrated.yaml", in.data_source, *in.rig, *in.model, s,
                           in.options, in.held);
    const RobotFile calibrated = LoadRobotFile(dir + "/calibrated.yaml");
    AddWorkspaceAccuracy(in, calibrated, &j);
    if (in.measured) {
      j["measured_points"] = MeasuredAccuracyJson(
          AccuracyAtMeasuredPoints(calibrated.robot, in.measured_setup, *in.measured));
      j["measured_points"]["file"] = in.measured_file;
    }
    j["calibrated_robot"] = "calibrated.yaml";
    // The same model as URDF, from the file just written (what lrcal export would write).
    WriteFileAtomically(dir + "/calibrated.urdf",
                        UrdfText(calibrated.robot, calibrated.robot.nominal_values()));
    j["calibrated_urdf"] = "calibrated.urdf";
  }
  WriteFileAtomically(dir + "/calibration.json", j.dump(2));
}

}  // namespace lrcal
