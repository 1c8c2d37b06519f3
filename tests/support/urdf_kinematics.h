// A URDF's own forward kinematics, composed independently of lrcal for the io tests (urdf_test.cc,
// urdf_like_test.cc): urdfdom parses, Eigen composes each joint's origin and then its motion.
#pragma once

#include <gtest/gtest.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <fstream>
#include <map>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace lrcal::testing {

/// The tool link's pose in the root frame at joint values q (the movable joints of the chain from
/// the root to `tool_link`, in order; rad, or m for a prismatic joint).
inline Eigen::Isometry3d UrdfForwardKinematics(const std::string& path,
                                               const std::string& tool_link,
                                               const std::vector<double>& q) {
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(path);
  EXPECT_TRUE(model) << path;
  std::vector<urdf::JointConstSharedPtr> chain;
  for (urdf::LinkConstSharedPtr link = model->getLink(tool_link); link->parent_joint;
       link = model->getLink(link->parent_joint->parent_link_name))
    chain.insert(chain.begin(), link->parent_joint);
  Eigen::Isometry3d x = Eigen::Isometry3d::Identity();
  std::size_t k = 0;
  for (const auto& joint : chain) {
    const urdf::Pose& o = joint->parent_to_joint_origin_transform;
    x = x * Eigen::Translation3d(o.position.x, o.position.y, o.position.z) *
        Eigen::Quaterniond(o.rotation.w, o.rotation.x, o.rotation.y, o.rotation.z);
    const Eigen::Vector3d axis(joint->axis.x, joint->axis.y, joint->axis.z);
    if (joint->type == urdf::Joint::FIXED) continue;
    if (joint->type == urdf::Joint::PRISMATIC)
      x = x * Eigen::Translation3d(q.at(k++) * axis);
    else
      x = x * Eigen::AngleAxisd(q.at(k++), axis.normalized());
  }
  EXPECT_EQ(k, q.size());
  return x;
}

/// `link`'s pose in the root frame with each movable joint at `q_by_name`'s value for its name
/// (a joint not named: 0), composed from the root down.
inline Eigen::Isometry3d UrdfLinkPose(const urdf::ModelInterface& model, const std::string& link,
                                      const std::map<std::string, double>& q_by_name) {
  Eigen::Isometry3d x = Eigen::Isometry3d::Identity();
  for (urdf::LinkConstSharedPtr l = model.getLink(link); l->parent_joint;
       l = model.getLink(l->parent_joint->parent_link_name)) {
    const urdf::Joint& joint = *l->parent_joint;
    const urdf::Pose& o = joint.parent_to_joint_origin_transform;
    Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
    step = step * Eigen::Translation3d(o.position.x, o.position.y, o.position.z) *
           Eigen::Quaterniond(o.rotation.w, o.rotation.x, o.rotation.y, o.rotation.z);
    const Eigen::Vector3d axis(joint.axis.x, joint.axis.y, joint.axis.z);
    const auto q = q_by_name.find(joint.name);
    const double value = q == q_by_name.end() ? 0.0 : q->second;
    if (joint.type == urdf::Joint::PRISMATIC)
      step = step * Eigen::Translation3d(value * axis);
    else if (joint.type != urdf::Joint::FIXED)
      step = step * Eigen::AngleAxisd(value, axis.normalized());
    x = step * x;
  }
  return x;
}

/// The pose of `tool_link` in `base_link`'s frame (any two links of the tree) at the named joint
/// values: both composed from the root, the base's pose inverted.
inline Eigen::Isometry3d UrdfPoseBetween(const std::string& path, const std::string& base_link,
                                         const std::string& tool_link,
                                         const std::map<std::string, double>& q_by_name) {
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(path);
  EXPECT_TRUE(model) << path;
  return UrdfLinkPose(*model, base_link, q_by_name).inverse() *
         UrdfLinkPose(*model, tool_link, q_by_name);
}

/// A copy of the URDF at `path`, written to `copy`, with every joint origin moved by up to 2 mm
/// and 2 mrad (uniform, from `seed`): a physically possible robot off the nominal one, the truth
/// of a simulated calibration of a tree. Returns `copy`.
inline std::string UrdfWithMovedOrigins(const std::string& path, unsigned seed,
                                        const std::string& copy) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  const std::string original = text.str();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> move(-2e-3, 2e-3);
  const std::regex origin(R"re(<origin xyz="([^"]*)" rpy="([^"]*)"/>)re");
  std::string out;
  std::size_t last = 0;
  for (auto it = std::sregex_iterator(original.begin(), original.end(), origin);
       it != std::sregex_iterator(); ++it) {
    out += original.substr(last, static_cast<std::size_t>(it->position()) - last);
    std::string moved[2];
    for (int g = 0; g < 2; ++g) {
      std::istringstream values((*it)[g + 1].str());
      double v;
      while (values >> v) {
        std::ostringstream number;
        number.precision(17);
        number << v + move(rng);
        moved[g] += (moved[g].empty() ? "" : " ") + number.str();
      }
    }
    out += "<origin xyz=\"" + moved[0] + "\" rpy=\"" + moved[1] + "\"/>";
    last = static_cast<std::size_t>(it->position() + it->length());
  }
  out += original.substr(last);
  std::ofstream(copy) << out;
  return copy;
}

}  // namespace lrcal::testing
