// The arm's non-geometric errors — joint compliance under gravity and thermal growth — as a
// wrapper around any measurement kind (measurement_kind.h), so that every sensor gets them at once.
//
// The model (NonGeometricModel): a measurement taken in environment E (environment.h: gravity g
// in the base frame, temperature T) sees
//  - each joint turned by its compliance under gravity's load: q'_j = q_j + c_j·τ_j(q, g), with
//    τ_j the generalised gravity force of the mass model at the commanded joint values on the
//    nominal geometry (kinematics/gravity_torque.h; N·m, or N for a prismatic joint) and c_j in
//    rad/(N·m) (m/N);
//  - every link length that is a geometric parameter (a_i, d_i) grown with the temperature:
//    ℓ' = ℓ·(1 + α·(T − T_ref)), α the links' coefficient (1/K), T_ref the temperature at which
//    the link values hold;
//  - a ranger's scale grown by α_r·(T − T_ref) (its reading (1 + s + α_r ΔT)·h + o).
// τ is taken at the commanded configuration on the nominal geometry: the deflection's effect on
// its own load (second order in c) is left out, the same way in simulation and identification.
//
// The estimated terms are the inner kind's own (less those held), then c_j for each joint whose
// compliance is estimated ("c1", rad/(N·m)), then "thermal_links" and "thermal_ranger" (1/K),
// each the deviation from the model's nominal value like every term (measurement_kind.h).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "lrcal/kinematics/forward_kinematics.h"
#include "lrcal/kinematics/gravity_torque.h"
#include "lrcal/measurement/environment.h"
#include "lrcal/measurement/measurement_kind.h"

namespace lrcal {

/// Thermal coefficients (a robot file's `thermal:`).
struct ThermalCoefficients {
  double reference_c = 20;  ///< °C: where the link values hold
  double links = 0;         ///< 1/K: every link length's coefficient (one material), or the
                            ///< common part added to `per_link`'s
  /// 1/K per link (a material per link); empty: `links` for every link. Link i's lengths grow by
  /// 1 + (links + per_link[i])·ΔT, so an estimated thermal_links is a correction common to all.
  Eigen::VectorXd per_link{};
  double ranger = 0;  ///< 1/K: the ranger's scale per kelvin
  /// Link i's coefficient (0-based), 1/K.
  double Link(int i) const {
    return links + (per_link.size() == 0 ? 0.0 : per_link[static_cast<Eigen::Index>(i)]);
  }
  /// True when no link grows.
  bool LinksStill() const { return links == 0 && (per_link.size() == 0 || per_link.isZero(0.0)); }
};

/// What the arm is beyond its geometry: masses, joint compliances, thermal coefficients, and the
/// environment a measurement that says none was taken in.
struct NonGeometricModel {
  MassModel masses;
  /// One compliance per joint (rad/(N·m); m/N for a prismatic joint); empty: every joint stiff.
  Eigen::VectorXd compliance;
  ThermalCoefficients thermal;
  Environment defaults = Environment::Ground();
  /// Joint j's compliance (0-based; 0 when `compliance` is empty).
  double Compliance(int j) const {
    return compliance.size() == 0 ? 0.0 : compliance[static_cast<Eigen::Index>(j)];
  }
  /// True when nothing non-geometric acts (no compliance or no mass, and no thermal coefficient):
  /// every environment reads as the geometric model.
  bool IsGeometric() const;
};

/// Which non-geometric terms are estimated.
struct NonGeometricTerms {
  std::vector<int> compliance_joints;  ///< 0-based joints whose c_j is estimated, ascending
  bool thermal_links = false;
  bool thermal_ranger = false;
  bool empty() const { return compliance_joints.empty() && !thermal_links && !thermal_ranger; }
  /// --estimate-compliance: "none", "all", or joints "j1,j3" (or "c1,c3", "1,3"); throws
  /// InputError (where = `source`) naming the value and what was expected.
  static std::vector<int> ParseCompliance(const std::string& text, int num_joints,
                                          const std::string& source);
  /// --estimate-thermal: "none", "links", "ranger", "all" (or "links,ranger").
  void ParseThermal(const std::string& text, const std::string& source);
};

/// "c3" for joint index 2.
std::string ComplianceTermName(int joint);
/// The joint (0-based) of a compliance term's name ("c3" → 2), or -1.
int ComplianceTermJoint(const std::string& name);
inline constexpr const char* kThermalLinksTerm = "thermal_links";
inline constexpr const char* kThermalRangerTerm = "thermal_ranger";

/// Any kind with the non-geometric model around it.
class EnvironmentMeasurement : public MeasurementKind {
 public:
  /// `inner`: the kind on `robot` (which must outlive this) with every term the model moves among
  /// its terms: a_i and d_i (the parameters among them) when a thermal coefficient is non-zero or
  /// estimated, θ_j (d_j for a prismatic joint) for each joint whose compliance is estimated,
  /// ranger_scale for the ranger's. `held`: inner terms not estimated (held at nominal). Throws
  /// InputError (where = `source`) naming a missing term or a held name the inner kind lacks.
  EnvironmentMeasurement(std::shared_ptr<const MeasurementKind> inner, const RobotModel& robot,
                         NonGeometricModel model, NonGeometricTerms estimate,
                         std::vector<std::string> held = {},
                         const std::string& source = "identification");

  const MeasurementKind& inner() const { return *inner_; }
  const NonGeometricModel& model() const { return model_; }
  const NonGeometricTerms& estimate() const { return estimate_; }

  const char* name() const override { return inner_->name(); }
  int rows_per_configuration() const override { return inner_->rows_per_configuration(); }
  bool RowIsAngle(int component) const override { return inner_->RowIsAngle(component); }
  const std::vector<std::string>& parameter_names() const override { return names_; }
  Eigen::VectorXd NominalValues() const override;
  std::unique_ptr<MeasurementEvaluator> Bind(const TargetedConfigurations& configs) const override;
  std::vector<std::string> MissReasons(const TargetedConfigurations& configs,
                                       const double* e) const override;
  std::unique_ptr<MeasurementKind> Without(const std::vector<std::string>& names) const override;

  /// Configuration i's environment with the model's defaults for what it does not give.
  Environment EnvironmentOf(const TargetedConfigurations& configs, int i) const {
    return configs.environment(i).Or(model_.defaults);
  }
  /// In words, why the non-geometric terms among `lost` (terms the rank analysis could not
  /// estimate at `configs`) are lost: a joint that carries no gravity torque, one temperature.
  std::vector<std::string> ExplainLostTerms(const TargetedConfigurations& configs,
                                            const std::vector<std::string>& lost) const;

  // For the evaluator.
  struct Layout {
    std::vector<int> exposed;         ///< inner column of each exposed inner term
    std::vector<int> exposed_length;  ///< per exposed term: its robot value index if a length, −1
    std::vector<double> exposed_base;  ///< per exposed length: its link's coefficient less `links`
    std::vector<int> length_columns;   ///< inner columns of the lengths thermal growth scales
    std::vector<double> length_nominal;  ///< their nominal values (m)
    std::vector<double> length_base;     ///< their link's coefficient less `links` (1/K)
    std::vector<int> joint_columns;      ///< per estimated compliance joint: its θ_j (d_j) column
    int ranger_scale_column = -1;        ///< inner column of ranger_scale, −1
  };
  const Layout& layout() const { return layout_; }

 private:
  void LayOutInnerTerms();
  void LayOutNonGeometricTerms();

  std::shared_ptr<const MeasurementKind> inner_;
  const RobotModel* robot_;
  NonGeometricModel model_;
  NonGeometricTerms estimate_;
  std::vector<std::string> held_;
  std::vector<std::string> names_;
  Layout layout_;
  std::string source_;
};

/// The tool poses of an arm with link values `link_values` (5N, SI) and the non-geometric model
/// `model` at each configuration of `configs` in its environment (model.defaults for what it
/// does not give): the thermal growth of its lengths and its joints' deflection under gravity.
/// What a study's validation compares in a validation environment.
std::vector<Pose<double>> EnvironmentToolPoses(const RobotModel& robot,
                                               const Eigen::VectorXd& link_values,
                                               const NonGeometricModel& model,
                                               const TargetedConfigurations& configs);

}  // namespace lrcal
