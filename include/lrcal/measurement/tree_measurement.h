// A tree's chains measured together: at each configuration of the whole robot, every chain's
// values (a tracker seeing both tools, each arm's ranger reading its plane). What design and
// studies choose among, since a configuration is the whole robot's joint vector.
//
// Rows: per configuration, the first chain's rows_per_configuration values, then the next
// chain's, and so on; every chain aims at the configuration's target (plane or reflector). The
// terms are those of MixedMeasurement over the chains (chain_measurement.h): shared links, base,
// planes and world-fixed terms once, each chain's own links and tool-borne terms labelled with
// its tool link. Data measured chain by chain at configurations of their own are identified with
// the MixedMeasurement of the same chains instead (lrcal identify --tool-link a,b).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "lrcal/measurement/chain_measurement.h"
#include "lrcal/measurement/mixed_measurement.h"

namespace lrcal {

class TreeMeasurement : public MeasurementKind {
 public:
  /// Throws InputError (where = "sensor") for no chains, chains of different robot joint counts,
  /// or a chain of a constraint kind (socket, contact: each chain is seated at configurations of
  /// its own, which one joint vector of the tree cannot hold).
  explicit TreeMeasurement(const std::vector<std::shared_ptr<const ChainMeasurement>>& chains);

  /// The chains' kind ("point") when they are all of one kind, else "mixed".
  const char* name() const override;
  int rows_per_configuration() const override { return rows_; }
  bool RowIsAngle(int component) const override;
  const std::vector<std::string>& parameter_names() const override {
    return mixed_.parameter_names();
  }
  Eigen::VectorXd NominalValues() const override { return mixed_.NominalValues(); }
  std::unique_ptr<MeasurementEvaluator> Bind(const TargetedConfigurations& configs) const override;
  /// Per configuration, the first chain's reason it misses ("ok" when every chain measures).
  std::vector<std::string> MissReasons(const TargetedConfigurations& configs,
                                       const double* e) const override;
  std::unique_ptr<MeasurementKind> Without(const std::vector<std::string>& names) const override;

 private:
  explicit TreeMeasurement(MixedMeasurement mixed);
  // The mixed layout (one entry per value) of `configs`: what Bind evaluates.
  TargetedConfigurations Expand(const TargetedConfigurations& configs) const;

  MixedMeasurement mixed_;
  int rows_ = 0;
  std::string name_;
};

}  // namespace lrcal
