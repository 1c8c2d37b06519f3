#include "lrcal/io/kinematics_report.h"

#include "lrcal/measurement/plane.h"

namespace lrcal {

namespace {

// Tool pose, beam and reading (and the Jacobian row) of configuration i, as JSON and a row of
// `table`.
// The ranger errors of the true model that its parameter set does not carry: they are applied to
// the reading after the model's own terms.
struct RangerErrors {
  double offset = 0, scale = 0;
};

ResultJson KinematicsRow(const MeasurementModel& model, const ModelPoint& point,
                         const TargetedConfigurations& configs, int i, const RangerSpec& ranger,
                         const RangerErrors& outside, bool jacobian, Table* table) {
  const ParameterSet& ps = model.parameters();
  std::vector<double> row(ps.size());
  double h;
  const double nb = model.Evaluate(point, configs, i, &h, jacobian ? row.data() : nullptr);
  h = (1 + outside.scale) * h + outside.offset;
  const BeamMiss miss = ClassifyReading(h, nb, ranger);
  const Pose<double> pose = ToolPose(point, configs, i);
  ResultJson j;
  j["q"] = std::vector<double>(configs.q(i), configs.q(i) + configs.num_joints());
  j["position"] = {pose.p_BT.x(), pose.p_BT.y(), pose.p_BT.z()};
  j["rotation"] = lrcal::ToJson(Eigen::MatrixXd(pose.R_BT));
  j["beam"] = {pose.R_BT(0, 2), pose.R_BT(1, 2), pose.R_BT(2, 2)};
  j["h"] = miss == BeamMiss::kNone ? ResultJson(h) : ResultJson();
  j["status"] = BeamMissName(miss);
  if (jacobian) {
    ResultJson g = ResultJson::object();
    for (int k = 0; k < ps.size(); ++k) g[ps.names[k]] = row[k];
    j["jacobian"] = g;
  }
  table->AddRow({std::to_string(i + 1), Fixed(pose.p_BT.x(), 6), Fixed(pose.p_BT.y(), 6),
                 Fixed(pose.p_BT.z(), 6), Fixed(pose.R_BT(0, 2), 6), Fixed(pose.R_BT(1, 2), 6),
                 Fixed(pose.R_BT(2, 2), 6),
                 miss == BeamMiss::kNone ? Fixed(h, 6) : std::string("—"), BeamMissName(miss)});
  return j;
}

Table JacobianTable(const std::vector<std::string>& names, const ResultJson& rows) {
  std::vector<std::string> header = {"#"};
  for (const auto& n : names) header.push_back(n);
  Table t(header, "Identification Jacobian rows dh/de (m/rad for angles, m/m for lengths)");
  for (std::size_t i = 0; i < rows.size(); ++i) {
    std::vector<std::string> r = {std::to_string(i + 1)};
    for (const auto& n : names) r.push_back(Fixed(rows[i]["jacobian"][n].get<double>(), 5));
    t.AddRow(r);
  }
  return t;
}

// `robot` with the true values of `truth` as its nominal ones.
RobotModel AtTrueValues(const RobotModel& robot, const Truth& truth) {
  std::vector<Link> links = robot.links();
  const Eigen::VectorXd values = truth.LinkValues(robot);
  for (int j = 0; j < robot.num_links(); ++j)
    for (int v = 0; v < kValuesPerLink; ++v) links[j].nominal[v] = values[kValuesPerLink * j + v];
  return RobotModel(robot.name(), links, robot.source, robot.base(), robot.tool());
}

}  // namespace

KinematicsReport ReportKinematics(const RobotFile& rig, const PlaneSet& planes,
                                  const ParameterSet& parameters, bool true_model,
                                  const TargetedConfigurations& configs, bool jacobian) {
  // The true model: every link value at its true value (the parameters of the set and the
  // fixed ones alike) and the ranger's true offset and scale, so that it reads what a
  // noise-free simulation reads.
  const RobotModel robot = true_model ? AtTrueValues(rig.robot, rig.truth) : rig.robot;
  const MeasurementModel model(robot, planes, parameters);
  std::vector<double> e(parameters.size(), 0.0);
  RangerErrors outside;
  if (true_model) {
    outside = {rig.truth.ranger_offset, rig.truth.ranger_scale};
    if (parameters.ranger_offset_index >= 0) {
      e[parameters.ranger_offset_index] = rig.truth.ranger_offset;
      outside.offset = 0;
    }
    if (parameters.ranger_scale_index >= 0) {
      e[parameters.ranger_scale_index] = rig.truth.ranger_scale;
      outside.scale = 0;
    }
  }
  ModelPoint point;
  model.Prepare(e.data(), &point);
  KinematicsReport report;
  report.poses =
      Table({"#", "x (m)", "y (m)", "z (m)", "beam x", "beam y", "beam z", "h (m)", "status"},
            std::string("Tool pose and laser reading per configuration (") +
                (true_model ? "true" : "nominal") + " model)");
  for (int i = 0; i < configs.size(); ++i)
    report.rows.push_back(
        KinematicsRow(model, point, configs, i, rig.ranger, outside, jacobian, &report.poses));
  if (jacobian) report.jacobian = JacobianTable(parameters.names, report.rows);
  return report;
}

std::string KinematicsReport::ToText() const {
  return poses.ToText() + (jacobian ? "\n" + jacobian->ToText() : std::string());
}

}  // namespace lrcal
