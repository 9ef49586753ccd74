// Stretches of one repeated reading (see stale_readings.hpp).
#include "lfd_core/segmentation/stale_readings.hpp"

#include <stdexcept>

namespace lfd {

std::vector<SampleSpan> repeatedReadings(const Eigen::MatrixXd& channels, std::size_t min_samples) {
  if (min_samples < 2) throw std::invalid_argument("repeated readings: min_samples must be >= 2");
  const auto same = [&](Eigen::Index k) {
    return (channels.row(k).array() == channels.row(k - 1).array()).all();
  };
  std::vector<SampleSpan> runs;
  Eigen::Index k = 1;
  while (k < channels.rows()) {
    if (!same(k)) {
      ++k;
      continue;
    }
    const Eigen::Index begin = k - 1;
    while (k < channels.rows() && same(k)) ++k;
    if (static_cast<std::size_t>(k - begin) >= min_samples)
      runs.push_back({static_cast<std::size_t>(begin), static_cast<std::size_t>(k)});
  }
  return runs;
}

}  // namespace lfd

namespace lfd {

std::vector<std::vector<SampleSpan>> staleReadings(const std::vector<Eigen::MatrixXd>& channels,
                                                   const std::vector<std::size_t>& min_samples) {
  if (channels.size() != min_samples.size())
    throw std::invalid_argument("stale readings: one minimum length per demo needed");
  std::vector<std::vector<SampleSpan>> runs(channels.size());
  std::vector<bool> whole(channels.size(), false);
  std::size_t never_repeat = 0, dead = 0;
  for (std::size_t d = 0; d < channels.size(); ++d) {
    runs[d] = repeatedReadings(channels[d], min_samples[d]);
    if (runs[d].empty()) ++never_repeat;
    // A sensor dead throughout says nothing of its noise (it is reported as constant).
    whole[d] = runs[d].size() == 1 && runs[d][0].begin == 0 &&
               runs[d][0].end == static_cast<std::size_t>(channels[d].rows());
    if (whole[d]) ++dead;
  }
  if (2 * never_repeat <= channels.size() - dead) {
    // A noise-free sensor repeats its rest reading: only where it never changed at all, while it
    // did in another demo, it did not measure.
    std::vector<std::vector<SampleSpan>> out(runs.size());
    for (std::size_t d = 0; d < runs.size(); ++d)
      if (whole[d] && dead < channels.size()) out[d] = runs[d];
    return out;
  }
  return runs;
}

}  // namespace lfd
