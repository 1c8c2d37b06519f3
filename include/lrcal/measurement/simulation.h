// Simulated laser readings from a "true" robot and plane.
//
// A reading at configuration i, repetition r is h_true(q_i) + σ·z, z the standard normal at
// index i·R + r of the noise stream (random.h); the measurand of a configuration is the mean of
// its R readings (slide 'Measurement Noise'). A configuration whose true beam misses the plane
// (laser_plane.h) has no reading: it is reported, never filled with a NaN.
//
// Beyond the paper, a real rig's disturbances (each off by default, each from its own family of
// draws, so that turning one on leaves the others' numbers unchanged):
//  - joint-encoder noise: reading r is taken at the true joint angles q_i + δq_r, δq_r ~ N(0,
//    σ_q² I) per joint, while the data records q_i (identification treats q as exact:
//    errors in variables). With draw_mean the mean of R readings is taken at q_i + δq̄,
//    δq̄ ~ N(0, σ_q²/R·I): the same distribution to first order in δq (the curvature term is
//    ~ L·σ_q², below 1e-8 m for σ_q ≤ 0.1 mrad);
//  - plane form error: the plane at configuration i's hit point is displaced along its normal
//    by ε_i ~ N(0, σ_form²), the same for all R readings there (a flatness deviation does not
//    average out): the reading changes by −ε_i/(n·b);
//  - outliers: each reading independently, with probability p, carries a gross error
//    ~ N(0, σ_out²). With draw_mean the K ~ Binomial(R, p) gross errors of a mean add
//    √K·σ_out·z/R — the same distribution.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "lrcal/core/random.h"
#include "lrcal/measurement/measurement_model.h"
#include "lrcal/measurement/measurement_set.h"
#include "lrcal/measurement/noise_model.h"

namespace lrcal {

/// The model readings of (link values, planes) at every configuration (on its own plane,
/// configs.target(i)), and each one's BeamMiss.
void ExactReadings(const RobotModel& robot, const Eigen::VectorXd& link_values,
                   const PlaneSet& planes, const RangerSpec& ranger,
                   const TargetedConfigurations& configs, std::vector<double>* h,
                   std::vector<BeamMiss>* misses);

/// Throws InputError unless every configuration's plane index is one of `planes`.
void CheckPlanesReferenced(const TargetedConfigurations& configs, const PlaneSet& planes);

/// Noisy readings of the true model. Fills `data` with the configurations that have a reading
/// (mean of R) and returns the number of configurations whose true beam missed; `misses` (if
/// given) gets every configuration's reason. `raw` (if given) gets every single reading,
/// configuration-major. `noise_slots` (if given) addresses each configuration's noise by a slot
/// (e.g. its index in the candidate pool: draws slot·R + r) instead of its position i, so that
/// two designs drawn from one pool see the same noise on the configurations they share.
int SimulateReadings(const RobotModel& robot, const Eigen::VectorXd& true_link_values,
                     const PlaneSet& true_planes, const RangerSpec& ranger,
                     const TargetedConfigurations& configs, const NoiseModel& noise,
                     const RandomStream& stream, MeasurementSet* data,
                     std::vector<BeamMiss>* misses = nullptr, std::vector<double>* raw = nullptr,
                     const std::vector<int>* noise_slots = nullptr);

/// The noisy part of SimulateReadings, from exact readings already computed (e.g. once per
/// Monte-Carlo cell when the truth and the design are fixed). Same results as SimulateReadings
/// when the noise does not disturb the geometry (!noise.DisturbsGeometry()); `per_reading`
/// (configs.size()·R values, if given) replaces exact_h for the raw readings.
int AddNoise(const std::vector<double>& exact_h, const std::vector<BeamMiss>& misses,
             const TargetedConfigurations& configs, const NoiseModel& noise,
             const RandomStream& stream, MeasurementSet* data, std::vector<double>* raw = nullptr,
             const std::vector<int>* noise_slots = nullptr,
             const std::vector<double>* per_reading = nullptr);

}  // namespace lrcal
