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
#include "lrcal/io/csv.h"
#include "lrcal/io/robot_data.h"
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

// A link by name, or an InputError naming the option (and study key) that gave it and every link.
urdf::LinkConstSharedPtr NamedLink(const urdf::ModelInterface& model, const std::string& path,
                                   const std::string& name, const std::string& option) {
  if (urdf::LinkConstSharedPtr link = model.getLink(name)) return link;
  std::vector<urdf::LinkSharedPtr> links;
  model.getLinks(links);
  std::vector<std::string> names;
  for (const auto& l : links) names.push_back(l->name);
  std::sort(names.begin(), names.end());
  throw InputError(path, "no link named '" + name + "' (--" + option + ", or a study's " +
                             std::string(option == "base-link" ? "base_link" : "tool_link") +
                             "); the links are " + JoinList(names));
}

std::string ChooseToolLink(const urdf::ModelInterface& model, const std::string& path,
                           const std::string& tool_link, const std::string& base_link) {
  if (!tool_link.empty()) return NamedLink(model, path, tool_link, "tool-link")->name;
  std::vector<std::string> leaves = LeafLinks(model);
  leaves.erase(std::remove(leaves.begin(), leaves.end(), base_link), leaves.end());
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

// The URDF at `path`, its tree checked (CheckUrdfTree) before urdfdom builds it.
urdf::ModelInterfaceSharedPtr ReadUrdfModel(const std::string& path) {
  if (!PathExists(path)) throw InputError(path, "no such file");
  CheckUrdfTree(path);
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(path);
  if (!model) throw InputError(path, "not a URDF that urdfdom can read (its message is above)");
  return model;
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

// The joints from the root down to `link`, root first.
std::vector<urdf::JointConstSharedPtr> JointsFromRoot(const urdf::ModelInterface& model,
                                                      urdf::LinkConstSharedPtr link) {
  std::vector<urdf::JointConstSharedPtr> joints;
  for (; link && link->parent_joint; link = model.getLink(link->parent_joint->parent_link_name))
    joints.push_back(link->parent_joint);
  std::reverse(joints.begin(), joints.end());
  return joints;
}

// The link's pose in the root frame at the zero configuration.
RigidTransform RootPoseAtZero(const std::vector<urdf::JointConstSharedPtr>& from_root) {
  RigidTransform pose;
  for (const auto& joint : from_root)
    pose = pose * FromUrdfPose(joint->parent_to_joint_origin_transform);
  return pose;
}

// One joint of the path from the base link to the tool link: traversed from parent to child
// (`reversed` false) or against the URDF's direction, from its child up to its parent.
struct PathJoint {
  urdf::JointConstSharedPtr joint;
  bool reversed = false;
};

// The path from `base` to `tool` through the tree: up from the base to the links' last common
// ancestor (each joint reversed, the base's own joint first), then down to the tool.
std::vector<PathJoint> PathBetween(const std::vector<urdf::JointConstSharedPtr>& root_to_base,
                                   const std::vector<urdf::JointConstSharedPtr>& root_to_tool) {
  std::size_t common = 0;
  while (common < root_to_base.size() && common < root_to_tool.size() &&
         root_to_base[common] == root_to_tool[common])
    ++common;
  std::vector<PathJoint> path;
  for (std::size_t k = root_to_base.size(); k > common; --k)
    path.push_back({root_to_base[k - 1], true});
  for (std::size_t k = common; k < root_to_tool.size(); ++k)
    path.push_back({root_to_tool[k], false});
  return path;
}

// A movable joint of the path as lrcal's joint axis in the base link's frame at q = 0: its line
// through the joint's frame (its child link's origin), its direction the URDF's axis, turned
// round for a joint traversed from child to parent (a positive joint value then moves the rest of
// the chain the other way: the product of exponentials of the inverse). Its value and range stay
// the URDF's.
JointAxis PathJointAxis(const urdf::ModelInterface& model, const PathJoint& step,
                        const RigidTransform& base_inverse, const std::string& path,
                        bool allow_mimic) {
  const urdf::Joint& joint = *step.joint;
  if (joint.mimic && !allow_mimic)
    throw InputError(path, "joint '" + joint.name +
                               "' mimics another; a chain with a coupled joint is read as a "
                               "tree's chain, which identify, identifiability and design take "
                               "(this command does not)");
  JointAxis axis;
  switch (joint.type) {
    case urdf::Joint::REVOLUTE:
    case urdf::Joint::CONTINUOUS:
      axis.joint = JointType::kRevolute;
      break;
    case urdf::Joint::PRISMATIC:
      axis.joint = JointType::kPrismatic;
      break;
    default:
      throw InputError(path, "joint '" + joint.name +
                                 "': lrcal handles revolute, continuous, prismatic and fixed "
                                 "joints, not floating, planar or unknown ones");
  }
  JointRange(joint, path, &axis);
  axis.name = joint.name;
  const RigidTransform frame =
      base_inverse * RootPoseAtZero(JointsFromRoot(model, model.getLink(joint.child_link_name)));
  axis.point = frame.translation;
  axis.direction = frame.rotation * Eigen::Vector3d(joint.axis.x, joint.axis.y, joint.axis.z);
  if (step.reversed) axis.direction = -axis.direction;
  if (!(axis.direction.norm() > 1e-12))
    throw InputError(path, "joint '" + joint.name + "': the axis is zero");
  return axis;
}

// The chain from base_link to tool_link (LoadUrdfRobotFile), a mimic joint on it a link of its
// own when `allow_mimic` (LoadUrdfChains couples it), else an error.
RobotFile LoadUrdfChain(const std::string& path, const std::string& tool_link,
                        const std::string& base_link, bool allow_mimic) {
  const urdf::ModelInterfaceSharedPtr model = ReadUrdfModel(path);
  const std::string base = base_link.empty() ? model->getRoot()->name : base_link;
  const urdf::LinkConstSharedPtr base_of_chain = NamedLink(*model, path, base, "base-link");
  const std::string tool = ChooseToolLink(*model, path, tool_link, base);
  if (tool == base)
    throw InputError(path, "the base link and the tool link are both '" + base +
                               "' (--base-link, --tool-link): a chain joins two links");
  const std::vector<urdf::JointConstSharedPtr> root_to_base = JointsFromRoot(*model, base_of_chain);
  const std::vector<urdf::JointConstSharedPtr> root_to_tool =
      JointsFromRoot(*model, model->getLink(tool));
  const RigidTransform base_inverse = RootPoseAtZero(root_to_base).Inverse();
  std::vector<JointAxis> axes;
  for (const PathJoint& step : PathBetween(root_to_base, root_to_tool))
    if (step.joint->type != urdf::Joint::FIXED)
      axes.push_back(PathJointAxis(*model, step, base_inverse, path, allow_mimic));
  if (axes.empty())
    throw InputError(path, "no movable joint between the " +
                               std::string(base_link.empty() ? "root" : "base") + " link '" + base +
                               "' and the tool link '" + tool + "'");
  RobotFile file;
  file.robot =
      RobotFromJointAxes(model->getName(), axes, base_inverse * RootPoseAtZero(root_to_tool), path);
  file.path = path;
  file.robot.source = path;
  return file;
}

}  // namespace

RobotFile LoadUrdfRobotFile(const std::string& path, const std::string& tool_link,
                            const std::string& base_link) {
  return LoadUrdfChain(path, tool_link, base_link, false);
}

bool UrdfChainIsCoupled(const std::string& path, const std::string& tool_link,
                        const std::string& base_link) {
  const RobotFile chain = LoadUrdfChain(path, tool_link, base_link, true);
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(path);
  for (const Link& link : chain.robot.links())
    if (model->getJoint(link.joint_name)->mimic) return true;
  return false;
}

namespace {

std::vector<std::string> ChainJointNames(const RobotModel& robot) {
  std::vector<std::string> names;
  for (const Link& link : robot.links()) names.push_back(link.joint_name);
  return names;
}

// Whether chains a and b have the same joints 0 … k + 1 (link k, from joint k to joint k + 1, is
// then the same D-H link in both; a chain's last link reaches its own tool).
bool ShareLink(const std::vector<std::string>& a, const std::vector<std::string>& b,
               std::size_t k) {
  return k + 1 < a.size() && k + 1 < b.size() &&
         std::equal(a.begin(), a.begin() + static_cast<std::ptrdiff_t>(k + 2), b.begin());
}

std::vector<std::string> LinkLabels(const std::vector<std::vector<std::string>>& joints,
                                    const std::vector<std::string>& labels, std::size_t c) {
  std::vector<std::string> out;
  for (std::size_t k = 0; k < joints[c].size(); ++k) {
    std::size_t first = c, sharing = 0;
    for (std::size_t d = 0; d < joints.size(); ++d)
      if (d == c || ShareLink(joints[c], joints[d], k)) {
        ++sharing;
        first = std::min(first, d);
      }
    out.push_back(sharing == joints.size() ? "" : labels[first]);
  }
  return out;
}

// The robot joint each chain link follows: its own, or for a mimic joint the joint it mimics,
// each named once in `tree->joint_names` (a mimicked joint off every chain last, with its range).
int RobotJoint(const urdf::ModelInterface& model, const urdf::Joint& joint, const std::string& path,
               UrdfChains* tree) {
  const std::string& name = joint.mimic ? joint.mimic->joint_name : joint.name;
  const auto it = std::find(tree->joint_names.begin(), tree->joint_names.end(), name);
  if (it != tree->joint_names.end()) return static_cast<int>(it - tree->joint_names.begin());
  const urdf::JointConstSharedPtr followed = model.getJoint(name);
  if (!followed || followed->mimic || followed->type == urdf::Joint::FIXED)
    throw InputError(path, "joint '" + joint.name + "' mimics '" + name +
                               "', which is not a movable joint of its own");
  JointAxis range;
  JointRange(*followed, path, &range);
  tree->joint_names.push_back(name);
  tree->q_min.push_back(range.q_min);
  tree->q_max.push_back(range.q_max);
  return static_cast<int>(tree->joint_names.size()) - 1;
}

// Chain c's place in the tree: its links' robot joints (after every chain's own joints are
// named), its couplings, its links' labels.
ChainOfTree PlaceChain(const urdf::ModelInterface& model, const std::string& path,
                       const std::vector<std::vector<std::string>>& joints,
                       const std::vector<std::string>& labels, std::size_t c, UrdfChains* tree) {
  ChainOfTree placement;
  placement.label = labels[c];
  const RobotModel& robot = tree->chains[c].robot;
  for (int k = 0; k < robot.num_links(); ++k) {
    const urdf::Joint& joint =
        *model.getJoint(robot.links()[static_cast<std::size_t>(k)].joint_name);
    placement.joints.push_back(RobotJoint(model, joint, path, tree));
    if (joint.mimic)
      placement.couplings.push_back({k, placement.joints.back(), joint.mimic->multiplier,
                                     joint.mimic->offset, joint.type == urdf::Joint::PRISMATIC});
  }
  placement.link_labels = LinkLabels(joints, labels, c);
  return placement;
}

}  // namespace

UrdfChains LoadUrdfChains(const std::string& path, const std::vector<std::string>& tool_links,
                          const std::string& base_link) {
  if (tool_links.empty()) throw InputError(path, "expected at least one tool link (--tool-link)");
  UrdfChains out;
  std::vector<std::string> tools = tool_links;
  for (std::string& tool : tools)
    if (tool.empty()) {  // the only end link other than the base link
      const urdf::ModelInterfaceSharedPtr model = ReadUrdfModel(path);
      tool =
          ChooseToolLink(*model, path, "", base_link.empty() ? model->getRoot()->name : base_link);
    }
  std::vector<std::vector<std::string>> joints;
  for (const std::string& tool : tools) {
    if (std::count(tools.begin(), tools.end(), tool) > 1)
      throw InputError(path, "the tool link '" + tool + "' is named twice (--tool-link)");
    out.chains.push_back(LoadUrdfChain(path, tool, base_link, true));
    joints.push_back(ChainJointNames(out.chains.back().robot));
  }
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(path);
  // The chains' own (not mimic) joints first, in chain order, with their ranges.
  for (std::size_t c = 0; c < out.chains.size(); ++c)
    for (const Link& link : out.chains[c].robot.links())
      if (!model->getJoint(link.joint_name)->mimic &&
          std::find(out.joint_names.begin(), out.joint_names.end(), link.joint_name) ==
              out.joint_names.end()) {
        out.joint_names.push_back(link.joint_name);
        out.q_min.push_back(link.q_min);
        out.q_max.push_back(link.q_max);
      }
  for (std::size_t c = 0; c < tools.size(); ++c)
    out.placements.push_back(PlaceChain(*model, path, joints, tools, c, &out));
  for (ChainOfTree& placement : out.placements)
    placement.robot_joints = static_cast<int>(out.joint_names.size());
  return out;
}

std::vector<std::string> UrdfChains::tool_links() const {
  std::vector<std::string> labels;
  for (const ChainOfTree& chain : placements) labels.push_back(chain.label);
  return labels;
}

UrdfChains LoadRobotChains(const std::string& path, const std::vector<std::string>& tool_links,
                           const std::string& base_link) {
  if (IsUrdfPath(path)) return LoadUrdfChains(path, tool_links, base_link);
  if (tool_links.size() > 1)
    throw InputError("--tool-link",
                     "several tool links are a tree's chains: --robot must be a "
                     "URDF, not '" +
                         path + "'");
  if (!tool_links.empty() && !tool_links[0].empty())
    throw InputError("--tool-link", "applies to a URDF robot; '" + path +
                                        "' is a robot YAML file (its last frame is the tool)");
  if (!base_link.empty())
    throw InputError("--base-link", "applies to a URDF robot; '" + path +
                                        "' is a robot YAML file (its base frame is the chain's "
                                        "first)");
  RobotFile file = LoadCoupledRobotFile(path);
  // Its joints named q<k> where the file names none: a log may then leave out a coupled joint's
  // column (ReadChainCsv fills it from the joint it follows).
  std::vector<Link> named = file.robot.links();
  for (std::size_t k = 0; k < named.size(); ++k)
    if (named[k].joint_name.empty()) named[k].joint_name = "q" + std::to_string(k + 1);
  const std::string source = file.robot.source;
  file.robot = RobotModel(file.robot.name(), named, path, file.robot.base(), file.robot.tool());
  file.robot.source = source;
  const std::vector<Link>& links = file.robot.links();
  UrdfChains out;
  ChainOfTree chain;
  chain.label = "tool";
  std::vector<int> index(links.size(), -1);
  for (std::size_t k = 0; k < links.size(); ++k) {
    const bool coupled =
        std::any_of(file.couplings.begin(), file.couplings.end(),
                    [&](const FileCoupling& f) { return f.link == static_cast<int>(k); });
    if (coupled) continue;
    index[k] = static_cast<int>(out.joint_names.size());
    out.joint_names.push_back(links[k].joint_name);
    out.q_min.push_back(links[k].q_min);
    out.q_max.push_back(links[k].q_max);
  }
  for (const FileCoupling& f : file.couplings) {
    const auto link = static_cast<std::size_t>(f.link);
    index[link] = index[static_cast<std::size_t>(f.follows)];
    chain.couplings.push_back(
        {f.link, index[link], f.multiplier, f.offset, links[link].joint == JointType::kPrismatic});
  }
  std::sort(chain.couplings.begin(), chain.couplings.end(),
            [](const JointCoupling& a, const JointCoupling& b) { return a.link < b.link; });
  chain.joints = index;
  chain.link_labels.assign(links.size(), "");
  chain.robot_joints = static_cast<int>(out.joint_names.size());
  out.chains.push_back(std::move(file));
  out.placements.push_back(std::move(chain));
  return out;
}

bool RobotChainIsCoupled(const std::string& path, const std::string& tool_link,
                         const std::string& base_link) {
  if (IsUrdfPath(path)) return UrdfChainIsCoupled(path, tool_link, base_link);
  return !LoadCoupledRobotFile(path).couplings.empty();
}

CsvTable ReadChainCsv(const std::string& path, const UrdfChains& tree, int chain) {
  const RobotFile& rig = tree.chains[static_cast<std::size_t>(chain)];
  CsvTable t = ReadRobotCsv(path, rig.robot);
  if (t.joint_columns.empty()) return t;  // q1..qN: every link's column, read as it is
  for (const JointCoupling& c : tree.placements[static_cast<std::size_t>(chain)].couplings) {
    const std::string& name = rig.robot.links()[static_cast<std::size_t>(c.link)].joint_name;
    if (t.Column(name) >= 0) continue;
    const std::string& followed = tree.joint_names[static_cast<std::size_t>(c.joint)];
    const int source = t.Column(followed);
    if (source < 0)
      throw InputError(Location(path, 1) + " column '" + CellExcerpt(followed) + "'",
                       "missing: the coupled joint '" + name +
                           "' follows it, and the file has "
                           "neither column");
    t.header.push_back(name);
    for (std::size_t r = 0; r < t.rows.size(); ++r)
      t.rows[r].push_back(FormatExact(c.multiplier * t.Number(r, source) + c.offset));
  }
  return t;
}

TargetedConfigurations ReadTreeConfigurations(const std::string& path, const UrdfChains& tree,
                                              const PlaneSet* planes) {
  CsvTable t = ReadCsv(path);
  t.joint_columns = tree.joint_names;
  const int n = static_cast<int>(tree.joint_names.size());
  TargetedConfigurations configs = Configurations(t, n, planes);
  for (int i = 0; i < configs.size(); ++i)
    for (int j = 0; j < n; ++j) {
      const double q = configs.q(i)[j];
      const auto u = static_cast<std::size_t>(j);
      if (q >= tree.q_min[u] - 1e-9 && q <= tree.q_max[u] + 1e-9) continue;
      throw InputError(Location(path, t.lines[static_cast<std::size_t>(i)]) + " column '" +
                           tree.joint_names[u] + "'",
                       FormatExact(q) + " is outside the joint's range [" +
                           FormatExact(tree.q_min[u]) + ", " + FormatExact(tree.q_max[u]) +
                           "] (the URDF's limits); joint values are in rad (m for a prismatic "
                           "joint): were they written in degrees or mm?");
    }
  return configs;
}

TargetedConfigurations UniformTreeConfigurations(const UrdfChains& tree, int count,
                                                 const RandomStream& stream) {
  const std::size_t n = tree.joint_names.size();
  TargetedConfigurations configs(static_cast<int>(n));
  configs.Reserve(count);
  std::vector<double> q(n);
  for (int i = 0; i < count; ++i) {
    for (std::size_t j = 0; j < n; ++j)
      q[j] = tree.q_min[j] + (tree.q_max[j] - tree.q_min[j]) *
                                 stream.Uniform(static_cast<std::uint64_t>(i) * n + j);
    configs.Add(q);
  }
  return configs;
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

namespace {

// A joint of the chain from the root to the tool link, in order.
struct ChainJoint {
  urdf::JointConstSharedPtr joint;
  TiXmlElement* element = nullptr;  // its <joint> in the document
  bool movable() const { return joint->type != urdf::Joint::FIXED; }
};

// Sets (or adds) the joint's <origin> to `t`.
void SetOrigin(TiXmlElement* joint, const RigidTransform& t) {
  TiXmlElement* origin = joint->FirstChildElement("origin");
  if (!origin) {
    TiXmlElement added("origin");
    origin = joint->FirstChild() ? joint->InsertBeforeChild(joint->FirstChild(), added)->ToElement()
                                 : joint->InsertEndChild(added)->ToElement();
  }
  const Eigen::Vector3d rpy = t.Rpy();
  origin->SetAttribute("xyz", FileNumber(t.translation.x()) + " " + FileNumber(t.translation.y()) +
                                  " " + FileNumber(t.translation.z()));
  origin->SetAttribute("rpy",
                       FileNumber(rpy.x()) + " " + FileNumber(rpy.y()) + " " + FileNumber(rpy.z()));
}

// The largest distance (m) and turn (rad) between the tool of `a` at `va` and of `b` at `vb` at
// the zero configuration and eight others spread over the joint ranges.
double LargestToolDifference(const RobotModel& a, const double* va, const RobotModel& b,
                             const double* vb) {
  double largest = 0;
  std::vector<double> q(static_cast<std::size_t>(a.num_links()), 0.0);
  for (int c = 0; c <= 8; ++c) {
    for (int k = 0; c > 0 && k < a.num_links(); ++k) {
      const Link& link = a.links()[static_cast<std::size_t>(k)];
      const double f = 0.5 + 0.4 * std::sin(1.7 * c + 2.3 * k);  // in (0.1, 0.9)
      q[static_cast<std::size_t>(k)] = link.q_min + f * (link.q_max - link.q_min);
    }
    const Pose<double> x = ForwardKinematics<double>(a, va, q.data());
    const Pose<double> y = ForwardKinematics<double>(b, vb, q.data());
    const Eigen::AngleAxisd turn(x.R_BT.transpose() * y.R_BT);
    largest = std::max({largest, (x.p_BT - y.p_BT).norm(), std::abs(turn.angle())});
  }
  return largest;
}

// The joints from the root to `tool` in order, each with its element of `doc`.
std::vector<ChainJoint> ChainToTool(const urdf::ModelInterface& model, const std::string& tool,
                                    TiXmlDocument* doc) {
  std::map<std::string, TiXmlElement*> elements;
  for (TiXmlElement* j = doc->RootElement()->FirstChildElement("joint"); j;
       j = j->NextSiblingElement("joint"))
    if (j->Attribute("name")) elements.emplace(j->Attribute("name"), j);
  std::vector<ChainJoint> chain;
  for (urdf::LinkConstSharedPtr link = model.getLink(tool); link && link->parent_joint;
       link = model.getLink(link->parent_joint->parent_link_name))
    chain.insert(chain.begin(), {link->parent_joint, elements[link->parent_joint->name]});
  return chain;
}

// The model must be of the URDF's chain (`mine`, its own model): as many movable joints, of the
// same kinds, its tool near the URDF's.
void CheckModelOfChain(const RobotModel& mine, const RobotModel& robot,
                       const Eigen::VectorXd& link_values, const std::string& original,
                       const std::string& tool) {
  if (mine.num_links() != robot.num_links())
    throw InputError(original, "the chain to '" + tool + "' has " +
                                   std::to_string(mine.num_links()) +
                                   " movable joints but the model has " +
                                   std::to_string(robot.num_links()) + " links");
  for (int k = 0; k < robot.num_links(); ++k)
    if (mine.links()[static_cast<std::size_t>(k)].joint !=
        robot.links()[static_cast<std::size_t>(k)].joint)
      throw InputError(original, "joint '" + mine.links()[static_cast<std::size_t>(k)].joint_name +
                                     "' is not of the kind of the model's link " +
                                     std::to_string(k + 1) + " (revolute or prismatic)");
  const double off =
      LargestToolDifference(mine, mine.nominal_values().data(), robot, link_values.data());
  if (!(off <= kUrdfLikeMismatch))
    throw InputError(original, "the model's tool is " + FileNumber(off * 1e3) +
                                   " mm (or mrad) from this URDF's own '" + tool +
                                   "': is the model a calibration of this robot and tool link?");
}

// Each movable joint's frame keeps its place on the model's frame before it: D_k = P_k⁻¹·J_k at
// the URDF's own model `mine` (P_k the D-H frame k-1, its z on joint k's axis; J_k the URDF's
// joint frame; both at q = 0) is a slide along and a turn about that axis.
std::vector<RigidTransform> JointSlides(const std::vector<ChainJoint>& chain,
                                        const RobotModel& mine) {
  std::vector<RigidTransform> slides;
  RigidTransform urdf_frame, dh_frame = mine.base();
  int k = 0;
  for (const ChainJoint& c : chain) {
    urdf_frame = urdf_frame * FromUrdfPose(c.joint->parent_to_joint_origin_transform);
    if (!c.movable()) continue;
    slides.push_back(dh_frame.Inverse() * urdf_frame);
    dh_frame = dh_frame * LinkRigidTransform(mine.nominal_values().data() + kValuesPerLink * k++);
  }
  return slides;
}

// Where the chain's origins go (UrdfLikeText): J_k = P_k·D_k at the calibrated model too, so
// O_k = F⁻¹·D_{k-1}⁻¹·A_{k-1}·D_k (F the fixed joints between; O_1 = F⁻¹·base·D_1), and the first
// fixed joint after the last movable one carries D_N⁻¹·A_N·tool·(the fixed joints after it)⁻¹.
class ChainOrigins {
 public:
  ChainOrigins(const RobotModel& robot, const Eigen::VectorXd& values,
               std::vector<RigidTransform> slides)
      : robot_(robot), values_(values), slides_(std::move(slides)) {}

  void Set(std::vector<ChainJoint>* chain, const std::string& original, const std::string& tool) {
    RigidTransform fixed, tail_rest;
    ChainJoint* tail = nullptr;  // the first fixed joint after the last movable one
    int k = 0;
    for (ChainJoint& c : *chain) {
      const RigidTransform origin = FromUrdfPose(c.joint->parent_to_joint_origin_transform);
      if (c.movable()) {
        SetOrigin(c.element, fixed.Inverse() * Before(k) * slides_[static_cast<std::size_t>(k)]);
        last_ = &c;
        last_fixed_ = fixed;
        fixed = RigidTransform();
        ++k;
      } else if (k < robot_.num_links()) {
        fixed = fixed * origin;
      } else if (!tail) {
        tail = &c;
      } else {
        tail_rest = tail_rest * origin;
      }
    }
    const RigidTransform tool_on_last = Link(robot_.num_links() - 1) * robot_.tool();
    if (tail)
      SetOrigin(tail->element, slides_.back().Inverse() * tool_on_last * tail_rest.Inverse());
    else
      SetLastOnTool(tool_on_last, original, tool);
  }

 private:
  RigidTransform Link(int i) const {
    return LinkRigidTransform(values_.data() + kValuesPerLink * i);
  }
  // The model's frame before joint k's slide, seen from the frame after joint k-1's motion.
  RigidTransform Before(int k) const {
    return k == 0 ? robot_.base()
                  : slides_[static_cast<std::size_t>(k - 1)].Inverse() * Link(k - 1);
  }
  // The tool link is the last joint's own: the model's tool must lie on that joint's axis (z of
  // the D-H frame before it) and turn z onto the URDF's axis; D_N is then the tool itself.
  void SetLastOnTool(const RigidTransform& tool_on_last, const std::string& original,
                     const std::string& tool) {
    const Eigen::Vector3d axis =
        Eigen::Vector3d(last_->joint->axis.x, last_->joint->axis.y, last_->joint->axis.z)
            .normalized();
    const double off = std::max(tool_on_last.translation.head<2>().norm(),
                                (tool_on_last.rotation.transpose().col(2) - axis).norm());
    if (off > 1e-12)
      throw InputError(original,
                       "the tool link '" + tool +
                           "' is the last movable joint's own child, so its frame turns about "
                           "that joint's axis, and the model's tool is off it by " +
                           FileNumber(off * 1e3) +
                           " mm (or mrad): choose a tool link behind a fixed joint (a flange), "
                           "whose origin can carry the calibrated tool");
    SetOrigin(last_->element,
              last_fixed_.Inverse() * Before(robot_.num_links() - 1) * tool_on_last);
  }

  const RobotModel& robot_;
  const Eigen::VectorXd& values_;
  std::vector<RigidTransform> slides_;
  ChainJoint* last_ = nullptr;  // the last movable joint, and the fixed joints before it
  RigidTransform last_fixed_;
};

}  // namespace

std::string UrdfLikeText(const std::string& original, const std::string& tool_link,
                         const RobotModel& robot, const Eigen::VectorXd& link_values) {
  const RobotFile own = LoadUrdfRobotFile(original, tool_link);  // the checks of any URDF
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(original);
  if (!model) throw InputError(original, "not a URDF that urdfdom can read (its message is above)");
  const std::string tool = ChooseToolLink(*model, original, tool_link, "");
  TiXmlDocument doc;
  if (!doc.LoadFile(original.c_str()) || !doc.RootElement())
    throw InputError(original, std::string("not XML that TinyXML can read: ") + doc.ErrorDesc());
  std::vector<ChainJoint> chain = ChainToTool(*model, tool, &doc);
  CheckModelOfChain(own.robot, robot, link_values, original, tool);
  ChainOrigins(robot, link_values, JointSlides(chain, own.robot)).Set(&chain, original, tool);
  TiXmlPrinter printer;
  printer.SetIndent("  ");
  doc.Accept(&printer);
  return printer.Str();
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
