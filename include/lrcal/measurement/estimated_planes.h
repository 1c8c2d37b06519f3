// The planes a measurement kind sees with the terms of each it estimates — the contact kind's
// (contact_measurement.h) and the scanner's (scanner_measurement.h): each plane's normal in its
// chart (plane.h NormalChart: "plane_u1", "plane_u2", ≈ rad, 0 at the nominal normal) and its
// offset ("plane_f", m), named by PlaneTermName ("plane2_u1", ... with several planes).
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "lrcal/measurement/parameter_set.h"
#include "lrcal/measurement/plane.h"
#include "lrcal/measurement/targeted_configurations.h"

namespace lrcal {

class EstimatedPlanes {
 public:
  /// Plane k at an estimate: its unit normal n(u) and ∂n/∂u (3 × 2), its offset f (m; the plane
  /// is n·x + f = 0 in the base frame), u, and the estimate's columns of u1, u2, f (-1 where
  /// held at nominal).
  struct State {
    Eigen::Vector3d normal;
    Eigen::Matrix<double, 3, 2> dn_du;
    double offset = 0, u[2] = {0, 0};
    int column[3] = {-1, -1, -1};
  };

  EstimatedPlanes() = default;
  /// `terms`: which of each plane's terms are estimated (empty: none; else one per plane). Each
  /// estimated term not in `fixed` is appended to `names`, its column the position it gets there.
  EstimatedPlanes(PlaneSet planes, std::vector<PlaneTerms> terms,
                  const std::vector<std::string>& fixed, std::vector<std::string>* names);

  const PlaneSet& planes() const { return planes_; }
  const std::vector<PlaneTerms>& terms() const { return terms_; }
  /// Every term `terms` makes estimable, fixed or not, in column order.
  std::vector<std::string> TermNames() const;
  State At(const double* e, int k) const;
  /// Writes each estimated offset's nominal value into `nominal` (u: the chart origin, 0).
  void SetNominal(Eigen::VectorXd* nominal) const;
  const NormalChart& chart(int k) const { return charts_[static_cast<std::size_t>(k)]; }
  /// Throws InputError ("configurations") unless `configs` have `num_joints` joints and name
  /// only planes of this set: "a configuration <verb> plane 3 but the set-up has 2 plane(s)"
  /// (verb: "touches", "is aimed at").
  void CheckConfigurations(const TargetedConfigurations& configs, int num_joints,
                           const std::string& verb) const;

 private:
  PlaneSet planes_;
  std::vector<PlaneTerms> terms_;
  std::vector<NormalChart> charts_;
  std::vector<std::array<int, 3>> columns_;  // per plane: u1, u2, f in e (-1 held)
};

}  // namespace lrcal
