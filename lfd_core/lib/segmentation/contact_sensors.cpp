// The joint segmentation's view of a task's sensors (see contact_sensors.hpp).
#include "lfd_core/segmentation/contact_sensors.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "lfd_core/segmentation/segmentation_pipeline.hpp"

namespace lfd {
namespace {

// Pearson correlation of two equally long series (0 when either is constant).
double correlation(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const Eigen::ArrayXd x = a.array() - a.mean(), y = b.array() - b.mean();
  const double den = std::sqrt((x * x).sum() * (y * y).sum());
  return den > 0 ? (x * y).sum() / den : 0.0;
}

}  // namespace

std::vector<Eigen::MatrixXd> sensorMagnitudes(const std::vector<FeatureMatrix>& demos,
                                              const std::vector<std::string>& names,
                                              const std::vector<std::size_t>& groups) {
  const std::size_t sensors =
      groups.empty() ? 0 : *std::max_element(groups.begin(), groups.end()) + 1;
  std::vector<Eigen::MatrixXd> out;
  for (const FeatureMatrix& demo : demos) {
    const Eigen::MatrixXd raw = demo.select(names).data;
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(demo.rows(), static_cast<Eigen::Index>(sensors));
    for (Eigen::Index c = 0; c < raw.cols(); ++c) {
      const auto g = static_cast<Eigen::Index>(groups[static_cast<std::size_t>(c)]);
      m.col(g) += (raw.col(c).array() - raw(0, c)).square().matrix();
    }
    out.push_back(m.cwiseSqrt());
  }
  for (Eigen::Index g = 0; g < static_cast<Eigen::Index>(sensors); ++g) {
    double top = 0.0;
    for (const Eigen::MatrixXd& m : out) top = std::max(top, m.col(g).maxCoeff());
    if (top > 0)
      for (Eigen::MatrixXd& m : out) m.col(g) /= top;
  }
  return out;
}

SensorSelection contactSensors(const std::vector<std::string>& names,
                               const std::vector<std::size_t>& groups,
                               const std::vector<Eigen::MatrixXd>& magnitudes,
                               const std::vector<Eigen::VectorXd>& speeds, double max_correlation,
                               std::vector<std::string>* warnings) {
  SensorSelection out;
  std::vector<bool> keep;
  for (Eigen::Index g = 0; g < (magnitudes.empty() ? 0 : magnitudes[0].cols()); ++g) {
    Eigen::Index rows = 0;
    for (const Eigen::VectorXd& v : speeds) rows += v.size();
    Eigen::VectorXd m(rows), v(rows);
    Eigen::Index at = 0;
    for (std::size_t d = 0; d < speeds.size(); ++d) {
      m.segment(at, speeds[d].size()) = magnitudes[d].col(g);
      v.segment(at, speeds[d].size()) = speeds[d];
      at += speeds[d].size();
    }
    const double r = correlation(m, v);
    keep.push_back(!(r > max_correlation));
    if (!keep.back()) {
      std::ostringstream msg;
      msg.precision(2);
      std::string sensor;
      for (std::size_t c = 0; c < names.size(); ++c)
        if (groups[c] == static_cast<std::size_t>(g))
          sensor += (sensor.empty() ? "" : ", ") + names[c];
      msg << "sensor " << sensor << " follows the robot's own speed (correlation " << r
          << "): its events are motion, not contact, and are not used as contacts";
      warnings->push_back(msg.str());
    }
  }
  std::vector<std::size_t> renumber(keep.size(), 0);
  std::size_t next = 0;
  for (std::size_t g = 0; g < keep.size(); ++g) renumber[g] = keep[g] ? next++ : 0;
  for (std::size_t c = 0; c < names.size(); ++c) {
    if (!keep[groups[c]]) continue;
    out.names.push_back(names[c]);
    out.groups.push_back(renumber[groups[c]]);
  }
  return out;
}

std::vector<std::vector<SampleSpan>> staleContactReadings(const std::vector<FeatureMatrix>& demos,
                                                          const SensorSelection& contact,
                                                          double min_seconds,
                                                          std::vector<std::string>* warnings) {
  std::vector<std::vector<SampleSpan>> out(demos.size());
  if (!(min_seconds > 0.0) || contact.names.empty()) return out;
  std::vector<std::size_t> min_samples;
  for (const FeatureMatrix& demo : demos)
    min_samples.push_back(std::max<std::size_t>(
        2, static_cast<std::size_t>(std::lround(min_seconds * sampleRateOf(demo)))));
  const std::size_t sensors = *std::max_element(contact.groups.begin(), contact.groups.end()) + 1;
  for (std::size_t g = 0; g < sensors; ++g) {
    std::vector<std::string> names;
    for (std::size_t c = 0; c < contact.names.size(); ++c)
      if (contact.groups[c] == g) names.push_back(contact.names[c]);
    std::vector<Eigen::MatrixXd> channels;
    for (const FeatureMatrix& demo : demos) channels.push_back(demo.select(names).data);
    const auto stale = staleReadings(channels, min_samples);
    for (std::size_t d = 0; d < demos.size(); ++d) {
      for (const SampleSpan& s : stale[d]) {
        out[d].push_back(s);
        if (s.begin == 0 && s.end == static_cast<std::size_t>(demos[d].rows())) continue;  // dead
        std::ostringstream msg;
        msg.precision(3);
        msg << "sensor " << names.front() << (names.size() > 1 ? ", ..." : "")
            << " repeats one reading from " << demos[d].timeAt(static_cast<Eigen::Index>(s.begin))
            << " s to " << demos[d].timeAt(static_cast<Eigen::Index>(s.end - 1))
            << " s (a driver's cached value?): its events there are not used";
        warnings->push_back("demonstration " + std::to_string(d) + ": " + msg.str());
      }
    }
  }
  return out;
}

SensorEvents measuredEvents(const Eigen::MatrixXd& channels, const SensoryEventConfig& config,
                            const std::vector<std::size_t>& groups,
                            const std::vector<SampleSpan>& stale) {
  const auto rows = static_cast<std::size_t>(channels.rows());
  std::size_t begin = 0;
  for (const SampleSpan& s : stale)
    if (s.begin == 0 && s.end < rows) begin = std::max(begin, s.end);
  if (begin == 0) return detectSensorEvents(channels, config, groups);
  const std::size_t block = std::max<std::size_t>(1, config.noise_block);
  begin = rows - std::min(rows, (rows - begin + block - 1) / block * block);
  SensorEvents events = detectSensorEvents(
      channels.bottomRows(static_cast<Eigen::Index>(rows - begin)), config, groups);
  for (std::size_t& i : events.all) i += begin;
  for (auto& sensor : events.per_sensor)
    for (std::size_t& i : sensor) i += begin;
  for (SensoryEvent& e : events.details) e.index += begin;
  for (std::size_t& i : events.zone_events) i += begin;
  return events;
}

void dropStaleEvents(const std::vector<SampleSpan>& stale, std::size_t margin,
                     SensorEvents* events) {
  const auto stale_at = [&](std::size_t index) {
    return std::any_of(stale.begin(), stale.end(), [&](const SampleSpan& s) {
      return index + margin >= s.begin && index <= s.end + margin;
    });
  };
  events->details.erase(std::remove_if(events->details.begin(), events->details.end(),
                                       [&](const SensoryEvent& e) { return stale_at(e.index); }),
                        events->details.end());
  events->all.erase(std::remove_if(events->all.begin(), events->all.end(), stale_at),
                    events->all.end());
}

}  // namespace lfd
