// Loads a robot file, simulates laser readings of its "true" arm, identifies the geometric
// parameters and prints the largest identified error against the truth (mm or mrad).
//   lrcal_consumer ROBOT.yaml
#include <cmath>
#include <iostream>

#include "lrcal/design/configuration_sampling.h"
#include "lrcal/identification/identification.h"
#include "lrcal/io/robot_file.h"
#include "lrcal/measurement/simulation.h"

int main(int argc, char** argv) {
  if (argc != 2) return std::cerr << "usage: lrcal_consumer ROBOT.yaml\n", 2;
  const lrcal::RobotFile rig = lrcal::LoadRobotFile(argv[1]);
  lrcal::SamplingOptions sampling;
  sampling.ranger = rig.ranger;
  // The file's planes (one here): 60 configurations whose beam hits them, readings, and the
  // identification against the same planes.
  const lrcal::PlaneSet& planes = *rig.planes;
  const lrcal::TargetedConfigurations configs = lrcal::SampleConfigurations(
      rig.robot, planes, {60}, lrcal::RandomStream(7, 0, 0, lrcal::RandomPurpose::kPool), sampling);
  lrcal::MeasurementSet data;
  lrcal::SimulateReadings(rig.robot, rig.truth.LinkValues(rig.robot), planes, rig.ranger, configs,
                          lrcal::NoiseModel{0.2e-3, 10},
                          lrcal::RandomStream(7, 0, 0, lrcal::RandomPurpose::kNoise), &data);
  const lrcal::MeasurementModel model(rig.robot, planes,
                                      lrcal::MakeParameterSet(rig.robot, lrcal::PlaneTerms{}));
  const lrcal::IdentificationSummary s = lrcal::Identify(model, data);
  // The file's true_errors: (RobotFile::truth), what the simulation read from.
  const Eigen::VectorXd true_errors = rig.truth.LinkErrors(rig.robot);
  double worst = 0;
  for (std::size_t k = 0; k < s.names.size(); ++k)
    worst = std::max(worst, std::abs(s.delta[k] - true_errors[rig.robot.FindValue(s.names[k])]));
  std::cout << s.BriefReport() << "\nlargest error of the identified parameters: " << worst * 1e3
            << " (mm or mrad)\n";
  return s.IsSolutionUsable() ? 0 : 1;
}
