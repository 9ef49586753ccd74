// The joint segmentation's view of a task's sensors: how far each is from rest, which of them
// report contact (and not the robot's own motion), where a contact sensor did not measure, and
// its events on the rows it measured.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "lfd_core/segmentation/sensory_events.hpp"
#include "lfd_core/segmentation/stale_readings.hpp"
#include "lfd_core/segmentation/time_series.hpp"

namespace lfd {

/// Per demo and sensor (rows = samples, columns = sensors as numbered by `groups`, one per
/// channel of `names`), how far the sensor's channels are from their level at the demo's start
/// (the norm over its channels), divided by the largest such distance over the task: which pad or
/// which axis feels a contact may differ between demos, that a contact is felt does not.
std::vector<Eigen::MatrixXd> sensorMagnitudes(const std::vector<FeatureMatrix>& demos,
                                              const std::vector<std::string>& names,
                                              const std::vector<std::size_t>& groups);

/// The sensor channels whose events count as contact, with each channel's sensor (renumbered
/// from 0).
struct SensorSelection {
  std::vector<std::string> names;
  std::vector<std::size_t> groups;
};

/// The sensors whose magnitude (sensorMagnitudes) is not explained by the robot's own speed
/// (`speeds`, per demo): their correlation, pooled over the demos, is at most `max_correlation`.
/// A loosely controlled arm's tracking error, or a wrist F/T feeling the hand's inertia, rises
/// and falls with every motion: its "contacts" are the motion's starts and stops, which the
/// motion evidence already holds. Each sensor left out is named in `warnings`.
SensorSelection contactSensors(const std::vector<std::string>& names,
                               const std::vector<std::size_t>& groups,
                               const std::vector<Eigen::MatrixXd>& magnitudes,
                               const std::vector<Eigen::VectorXd>& speeds, double max_correlation,
                               std::vector<std::string>* warnings);

/// Per demo, where a contact sensor repeated one reading for at least `min_seconds` although it
/// has noise (stale_readings.hpp): the union over the sensors, each stretch named in `warnings`
/// (a sensor dead throughout is not: it is reported as constant elsewhere). None for
/// min_seconds <= 0.
std::vector<std::vector<SampleSpan>> staleContactReadings(const std::vector<FeatureMatrix>& demos,
                                                          const SensorSelection& contact,
                                                          double min_seconds,
                                                          std::vector<std::string>* warnings);

/// The events of `channels` (rows = samples) detected from where the sensor began to measure: a
/// stale stretch that opens the demo is left out. Over a driver's cached reading the noise is nil,
/// and a floor set by that quiet makes every wiggle of the contact an event (stale F/T: touch and
/// release lost among level steps); the rest level is the first measured one. The part kept ends
/// whole noise blocks at the demo's end (SensoryEventConfig::noise_block): its only quiet second
/// may be its last (the rest after the retract).
SensorEvents measuredEvents(const Eigen::MatrixXd& channels, const SensoryEventConfig& config,
                            const std::vector<std::size_t>& groups,
                            const std::vector<SampleSpan>& stale);

/// Drops the events within `margin` samples of a stale stretch: the sensor wakes up there.
void dropStaleEvents(const std::vector<SampleSpan>& stale, std::size_t margin,
                     SensorEvents* events);

}  // namespace lfd
