#include "lrcal/io/urdf.h"

#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "lrcal/core/data_dir.h"
#include "lrcal/core/error.h"
#include "lrcal/core/settings.h"
#include "lrcal/core/strings.h"
#include "lrcal/kinematics/dh_conversion.h"
#include "lrcal/kinematics/forward_kinematics.h"

namespace lrcal {

bool IsUrdfPath(const std::string& path) {
  if (path.size() < 5) return false;
  std::string ext = path.substr(path.size() - 5);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".urdf";
}

namespace {

std::string JoinList(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

RigidTransform FromUrdfPose(const urdf::Pose& pose) {
  RigidTransform t;
  const urdf::Rotation& r = pose.rotation;
  t.rotation = Eigen::Quaterniond(r.w, r.x, r.y, r.z).normalized().toRotationMatrix();
  t.translation = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  return t;
}

// The links with no child link: candidates for the tool.
std::vector<std::string> LeafLinks(const urdf::ModelInterface& model) {
  std::vector<urdf::LinkSharedPtr> links;
  model.getLinks(links);
  std::vector<std::string> leaves;
  for (const auto& link : links)
    if (link->child_links.empty()) leaves.push_back(link->name);
  std::sort(leaves.begin(), leaves.end());
  return leaves;
}

std::string ChooseToolLink(const urdf::ModelInterface& model, const std::string& path,
                           const std::string& tool_link) {
  if (!tool_link.empty()) {
    if (!model.getLink(tool_link)) {
      std::vector<urdf::LinkSharedPtr> links;
      model.getLinks(links);
      std::vector<std::string> names;
      for (const auto& link : links) names.push_back(link->name);
      std::sort(names.begin(), names.end());
      throw InputError(path, "no link named '" + tool_link +
                                 "' (--tool-link, or a study's tool_link); the links are " +
                                 JoinList(names));
    }
    return tool_link;
  }
  const std::vector<std::string> leaves = LeafLinks(model);
  if (leaves.size() != 1)
    throw InputError(path, "the URDF has " + std::to_string(leaves.size()) + " end links (" +
                               JoinList(leaves) +
                               "): give the ranger's link with --tool-link NAME (a study: "
                               "tool_link: NAME)");
  return leaves.front();
}

// Each link's parent link (from the first joint naming it as child), read from the URDF's
// <joint> elements with TinyXML. A joint whose parent is its child is an InputError.
std::map<std::string, std::string> ParentLinks(const TiXmlElement& robot, const std::string& path) {
  std::map<std::string, std::string> parent_of;
  for (const TiXmlElement* j = robot.FirstChildElement("joint"); j;
       j = j->NextSiblingElement("joint")) {
    const TiXmlElement* parent = j->FirstChildElement("parent");
    const TiXmlElement* child = j->FirstChildElement("child");
    const char* p = parent ? parent->Attribute("link") : nullptr;
    const char* c = child ? child->Attribute("link") : nullptr;
    if (!p || !c) continue;  // urdfdom names the joint
    const char* name = j->Attribute("name");
    if (std::string(p) == c)
      throw InputError(path, "joint '" + std::string(name ? name : "") + "' has link '" + c +
                                 "' as both its parent and its child: a URDF is a tree");
    parent_of.emplace(c, p);
  }
  return parent_of;
}

// Walks up from every link, iteratively; a link met twice on one walk closes a cycle.
void CheckNoCycle(const std::map<std::string, std::string>& parent_of, const std::string& path) {
  std::set<std::string> reaches_root;
  for (const auto& start : parent_of) {
    std::vector<std::string> walk;
    std::set<std::string> on_walk;
    std::string link = start.first;
    while (!reaches_root.count(link)) {
      if (!on_walk.insert(link).second) {
        std::string cycle;
        for (auto it = std::find(walk.begin(), walk.end(), link); it != walk.end(); ++it)
          cycle += "'" + *it + "' -> ";
        throw InputError(path, "the joints form a cycle: " + cycle + "'" + link +
                                   "' (each link's parent, in turn); a URDF is a tree");
      }
      walk.push_back(link);
      const auto up = parent_of.find(link);
      if (up == parent_of.end()) break;
      link = up->second;
    }
    reaches_root.insert(walk.begin(), walk.end());
  }
}

// A URDF must be UTF-8 text: TinyXML (2.6.2, under urdfdom too) reads past the end of its buffer
// on a truncated multi-byte sequence (found by fuzzing, tests/fuzz/corpus/urdf), so the bytes are
// checked first, line by line, and the first bad line named.
void CheckUtf8Text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number)
    if (!IsValidUtf8(line))
      throw InputError(Location(path, number),
                       "not UTF-8 text (an invalid or truncated byte sequence on this line): a "
                       "URDF is read as UTF-8 XML");
}

// A URDF's tree checked before urdfdom builds it: urdfdom walks the tree by recursion (a very
// deep chain overflows the stack) and lrcal walks from the tool link to the root (a cycle would
// never end). Read with TinyXML (urdfdom's own XML reader), iteratively: at most kMaxUrdfLinks
// links, no joint whose parent is its child, no cycle. Anything else (a malformed file, a link
// with two parents) is left to urdfdom's own checks.
void CheckUrdfTree(const std::string& path) {
  CheckUtf8Text(path);
  TiXmlDocument doc(path.c_str());
  if (!doc.LoadFile()) return;  // urdfdom reports the XML error
  const TiXmlElement* robot = doc.FirstChildElement("robot");
  if (!robot) return;
  int links = 0;
  for (const TiXmlElement* e = robot->FirstChildElement("link"); e;
       e = e->NextSiblingElement("link"))
    ++links;
  if (links > kMaxUrdfLinks)
    throw InputError(path, "the URDF has " + std::to_string(links) +
                               " links; lrcal reads at most " + std::to_string(kMaxUrdfLinks));
  CheckNoCycle(ParentLinks(*robot, path), path);
}

// The joint's range: revolute/prismatic from <limit>, continuous ±π.
void JointRange(const urdf::Joint& joint, const std::string& path, JointAxis* axis) {
  if (joint.type == urdf::Joint::CONTINUOUS) return;  // the default ±π
  if (!joint.limits || !(joint.limits->lower < joint.limits->upper))
    throw InputError(path, "joint '" + joint.name +
                               "': expected <limit lower=... upper=...> with lower < upper");
  axis->q_min = joint.limits->lower;
  axis->q_max = joint.limits->upper;
}

}  // namespace

RobotFile LoadUrdfRobotFile(const std::string& path, const std::string& tool_link) {
  if (!PathExists(path)) throw InputError(path, "no such file");
  CheckUrdfTree(path);
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(path);
  if (!model) throw InputError(path, "not a URDF that urdfdom can read (its message is above)");
  const std::string tool = ChooseToolLink(*model, path, tool_link);
  // The joints from the root to the tool link.
  std::vector<urdf::JointConstSharedPtr> chain;
  for (urdf::LinkConstSharedPtr link = model->getLink(tool); link && link->parent_joint;
       link = model->getLink(link->parent_joint->parent_link_name))
    chain.push_back(link->parent_joint);
  std::reverse(chain.begin(), chain.end());
  std::vector<JointAxis> axes;
  RigidTransform pose;  // of the current link in the root frame, at q = 0
  for (const auto& joint : chain) {
    pose = pose * FromUrdfPose(joint->parent_to_joint_origin_transform);
    if (joint->type == urdf::Joint::FIXED) continue;
    if (joint->mimic)
      throw InputError(
          path, "joint '" + joint->name + "' mimics another; lrcal needs independent joints");
    JointAxis axis;
    switch (joint->type) {
      case urdf::Joint::REVOLUTE:
      case urdf::Joint::CONTINUOUS:
        axis.joint = JointType::kRevolute;
        break;
      case urdf::Joint::PRISMATIC:
        axis.joint = JointType::kPrismatic;
        break;
      default:
        throw InputError(path, "joint '" + joint->name +
                                   "': lrcal handles revolute, continuous, prismatic and fixed "
                                   "joints, not floating, planar or unknown ones");
    }
    JointRange(*joint, path, &axis);
    axis.name = joint->name;
    axis.point = pose.translation;
    axis.direction = pose.rotation * Eigen::Vector3d(joint->axis.x, joint->axis.y, joint->axis.z);
    if (!(axis.direction.norm() > 1e-12))
      throw InputError(path, "joint '" + joint->name + "': the axis is zero");
    axes.push_back(axis);
  }
  if (axes.empty())
    throw InputError(path, "no movable joint between the root link '" + model->getRoot()->name +
                               "' and the tool link '" + tool + "'");
  RobotFile file;
  file.robot = RobotFromJointAxes(model->getName(), axes, pose, path);
  file.path = path;
  file.robot.source = path;
  return file;
}

namespace {

std::string Origin(const RigidTransform& t) {
  const Eigen::Vector3d rpy = t.Rpy();
  return "<origin xyz=\"" + FileNumber(t.translation.x()) + " " + FileNumber(t.translation.y()) +
         " " + FileNumber(t.translation.z()) + "\" rpy=\"" + FileNumber(rpy.x()) + " " +
         FileNumber(rpy.y()) + " " + FileNumber(rpy.z()) + "\"/>";
}

std::string XmlEscaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

}  // namespace

std::string UrdfText(const RobotModel& robot, const Eigen::VectorXd& values) {
  std::string t =
      "<?xml version=\"1.0\"?>\n<!-- Written by lrcal export: D-H + beta chain as "
      "URDF joints (docs/URDF.md). -->\n<robot name=\"" +
      XmlEscaped(robot.name()) + "\">\n  <link name=\"base_link\"/>\n";
  RigidTransform origin = robot.base();  // what precedes joint i's motion, in link i-1
  for (int i = 0; i < robot.num_links(); ++i) {
    const Link& link = robot.links()[i];
    const std::string parent = i == 0 ? "base_link" : "link" + std::to_string(i);
    const std::string child = "link" + std::to_string(i + 1);
    t += "  <link name=\"" + child + "\"/>\n  <joint name=\"joint" + std::to_string(i + 1) +
         "\" type=\"" + (link.joint == JointType::kPrismatic ? "prismatic" : "revolute") +
         "\">\n    <parent link=\"" + parent + "\"/>\n    <child link=\"" + child + "\"/>\n    " +
         Origin(origin) + "\n    <axis xyz=\"0 0 1\"/>\n    <limit lower=\"" +
         FileNumber(link.q_min) + "\" upper=\"" + FileNumber(link.q_max) +
         "\" effort=\"0\" velocity=\"0\"/>\n  </joint>\n";
    origin = LinkRigidTransform(values.data() + kValuesPerLink * i);
  }
  t += "  <link name=\"tool\"/>\n  <joint name=\"tool_joint\" type=\"fixed\">\n    <parent "
       "link=\"link" +
       std::to_string(robot.num_links()) + "\"/>\n    <child link=\"tool\"/>\n    " +
       Origin(origin * robot.tool()) + "\n  </joint>\n</robot>\n";
  return t;
}

std::string DhTableText(const RobotModel& robot, const Eigen::VectorXd& values) {
  std::string t = "# D-H + beta table of " + robot.name() +
                  " (lrcal export): A_i = Rz(theta0 + q) Tz(d) Tx(a) Rx(alpha) Ry(beta)\n";
  const std::pair<const char*, const RigidTransform*> frames[] = {{"base", &robot.base()},
                                                                  {"tool", &robot.tool()}};
  for (const auto& [key, transform] : frames) {
    const Eigen::Vector3d xyz = transform->translation, rpy = transform->Rpy();
    t += std::string("# ") + key + " xyz_m: " + FileNumber(xyz.x()) + " " + FileNumber(xyz.y()) +
         " " + FileNumber(xyz.z()) + " rpy_rad: " + FileNumber(rpy.x()) + " " +
         FileNumber(rpy.y()) + " " + FileNumber(rpy.z()) + "\n";
  }
  t += "link,joint,theta0_rad,d_m,a_m,alpha_rad,beta_rad,q_min,q_max,parameters\n";
  for (int i = 0; i < robot.num_links(); ++i) {
    const Link& link = robot.links()[i];
    const double* v = values.data() + kValuesPerLink * i;
    std::vector<std::string> parameters;
    for (int k = 0; k < kValuesPerLink; ++k)
      if (link.is_parameter[k]) parameters.emplace_back(LinkValueName(k));
    std::string list;
    for (const std::string& p : parameters) list += (list.empty() ? "" : " ") + p;
    t += std::to_string(i + 1) + "," +
         (link.joint == JointType::kPrismatic ? "prismatic" : "revolute") + "," +
         FileNumber(v[kTheta]) + "," + FileNumber(v[kD]) + "," + FileNumber(v[kA]) + "," +
         FileNumber(v[kAlpha]) + "," + FileNumber(v[kBeta]) + "," + FileNumber(link.q_min) + "," +
         FileNumber(link.q_max) + "," + list + "\n";
  }
  return t;
}

std::string RobotExportText(const RobotFile& rig, const std::string& format,
                            const std::optional<PlaneSet>& planes) {
  const Eigen::VectorXd& values = rig.robot.nominal_values();
  if (format == "urdf") return UrdfText(rig.robot, values);
  if (format == "dh-table") return DhTableText(rig.robot, values);
  if (format == "yaml")
    return "# Written by lrcal export from " + rig.path + " (format: docs/FILE_FORMATS.md).\n" +
           RobotFileText(rig, values, planes, rig.robot.name(),
                         rig.calibration ? &*rig.calibration : nullptr);
  throw SettingError(SettingSpec::Named("export", "format", "format", "urdf, dh-table or yaml"),
                     "expected urdf, dh-table or yaml; got '" + format + "'");
}

}  // namespace lrcal
