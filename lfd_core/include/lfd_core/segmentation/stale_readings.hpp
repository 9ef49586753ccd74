// Where a sensor repeats one reading: a driver that publishes its cached value until the device
// answers, or after it stops answering. A sensor with noise never gives the same reading twice in
// a row on all its channels; over such a stretch it did not measure, and its events at the ends
// of the stretch are the driver waking up (a jump to wherever the force already was), not an
// interaction. Whether a sensor has noise is for the caller to know: a simulated touch pad reads
// exactly 0 at rest, and repeats readings all the time (the joint segmentation asks the other
// demonstrations: a sensor that never repeats a reading in most of them has noise).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace lfd {

/// Samples [begin, end).
struct SampleSpan {
  std::size_t begin = 0, end = 0;
};

/// The stretches of at least `min_samples` rows (>= 2) where every column of `channels` (rows =
/// samples, one sensor's channels) holds one value exactly. Throws std::invalid_argument for
/// min_samples < 2.
std::vector<SampleSpan> repeatedReadings(const Eigen::MatrixXd& channels, std::size_t min_samples);

}  // namespace lfd

namespace lfd {

/// Per demo, the stretches where one sensor did not measure: its repeated readings (at least
/// min_samples[d] rows in demo d), when the sensor has noise, i.e. when more than half the demos
/// (`channels`: the sensor's columns per demo) repeat no reading that long, demos where it holds
/// one reading throughout (dead) not counted. Otherwise (a noise-free sensor, which repeats its
/// rest reading) only the demos where it holds one reading throughout while it changes in
/// another (dead). Throws std::invalid_argument on a size mismatch.
std::vector<std::vector<SampleSpan>> staleReadings(const std::vector<Eigen::MatrixXd>& channels,
                                                   const std::vector<std::size_t>& min_samples);

}  // namespace lfd
