#include "lrcal/io/kinematics_report.h"

#include "lrcal/measurement/plane.h"

namespace lrcal {

namespace {

// Tool pose, beam and reading (and the Jacobian row) of configuration i, as JSON and a row of
// `table`.
ResultJson KinematicsRow(const MeasurementModel& model, const ModelPoint& point,
                         const ConfigurationSet& configs, int i, const RangerSpec& ranger,
                         bool jacobian, Table* table) {
  const ParameterSet& ps = model.parameters();
  std::vector<double> row(ps.size());
  double h;
  const double nb = model.Evaluate(point, configs, i, &h, jacobian ? row.data() : nullptr);
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

}  // namespace

KinematicsReport ReportKinematics(const MeasurementModel& model, bool true_model,
                                  const ConfigurationSet& configs, const RangerSpec& ranger,
                                  bool jacobian) {
  const RobotModel& robot = model.robot();
  const ParameterSet& ps = model.parameters();
  const Eigen::VectorXd values = true_model ? robot.true_values() : robot.nominal_values();
  // The Jacobian is taken at the chosen model: its robot deltas relative to nominal.
  std::vector<double> e(ps.size(), 0.0);
  for (int k = 0; k < ps.num_robot(); ++k)
    e[k] = values[ps.robot_values[k]] - robot.nominal_values()[ps.robot_values[k]];
  ModelPoint point;
  model.Prepare(e.data(), &point);
  KinematicsReport report;
  report.poses =
      Table({"#", "x (m)", "y (m)", "z (m)", "beam x", "beam y", "beam z", "h (m)", "status"},
            std::string("Tool pose and laser reading per configuration (") +
                (true_model ? "true" : "nominal") + " model)");
  for (int i = 0; i < configs.size(); ++i)
    report.rows.push_back(KinematicsRow(model, point, configs, i, ranger, jacobian, &report.poses));
  if (jacobian) report.jacobian = JacobianTable(ps.names, report.rows);
  return report;
}

std::string KinematicsReport::ToText() const {
  return poses.ToText() + (jacobian ? "\n" + jacobian->ToText() : std::string());
}

}  // namespace lrcal
