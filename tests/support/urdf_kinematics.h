// A URDF's own forward kinematics, composed independently of lrcal for the io tests (urdf_test.cc,
// urdf_like_test.cc): urdfdom parses, Eigen composes each joint's origin and then its motion.
#pragma once

#include <gtest/gtest.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
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

}  // namespace lrcal::testing
