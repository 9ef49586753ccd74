// The zone-guided search of multivariate ClaSP (zone_guided_search.hpp).
#include "lfd_core/segmentation/zone_guided_search.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace lfd {

ZoneGuide::ZoneGuide(const MultivariateSegmentationConfig& config, std::size_t min_s, std::size_t n)
    : config_(config),
      zones_(config.candidate_zones_for ? config.candidate_zones_for(min_s)
                                        : config.candidate_zones),
      restricted_(config.candidate_zones_for || !zones_.empty()),
      one_per_zone_(config.zone_anchors.empty()),
      used_(zones_.size(), false),
      n_(n) {
  initNeededLog10P();
}

int ZoneGuide::zoneOf(std::size_t t) const {
  for (std::size_t z = 0; z < zones_.size(); ++z)
    if (zones_[z].contains(t)) return static_cast<int>(z);
  return -1;
}

bool ZoneGuide::open(std::size_t t) const {
  if (!restricted_) return true;
  const int z = zoneOf(t);
  return z >= 0 && !(one_per_zone_ && used_[static_cast<std::size_t>(z)]);
}

std::vector<bool> ZoneGuide::closedZones(std::size_t begin, std::size_t end,
                                         const Eigen::VectorXd& penalized) const {
  std::vector<bool> closed(zones_.size(), false);
  if (!restricted_ || one_per_zone_) return closed;
  std::vector<bool> anchored(zones_.size(), false);
  for (std::size_t a : config_.zone_anchors) {
    const int z = zoneOf(a);
    if (z >= 0 && a >= begin && a < end &&
        !std::isnan(penalized[static_cast<Eigen::Index>(a - begin)]))
      anchored[static_cast<std::size_t>(z)] = true;
  }
  for (std::size_t z = 0; z < zones_.size(); ++z) closed[z] = !anchored[z];
  return closed;
}

Eigen::Index ZoneGuide::anchorFor(const Eigen::VectorXd& profile, std::size_t begin,
                                  Eigen::Index t) const {
  if (!restricted_) return -1;
  const int zone = zoneOf(begin + static_cast<std::size_t>(t));
  Eigen::Index nearest = -1;
  bool nearest_preferred = false;
  for (std::size_t i = 0; i < config_.zone_anchors.size(); ++i) {
    const std::size_t a = config_.zone_anchors[i];
    if (a < begin || a >= begin + static_cast<std::size_t>(profile.size())) continue;
    const Eigen::Index rel = static_cast<Eigen::Index>(a - begin);
    if (zoneOf(a) != zone || std::isnan(profile[rel])) continue;
    const bool preferred = isPreferred(i);
    if (nearest >= 0 && nearest_preferred && !preferred) continue;
    if (nearest < 0 || (preferred && !nearest_preferred) ||
        std::abs(rel - t) < std::abs(nearest - t)) {
      nearest = rel;
      nearest_preferred = preferred;
    }
  }
  return nearest;
}

// Outside zones a long demo needs more evidence (significance_per_sample): the rank-sum test's
// log p grows with the number of subsequences for the same split quality.
double ZoneGuide::neededLog10P(std::size_t argmax) const {
  if (restricted_) return zone_needed_[static_cast<std::size_t>(zoneOf(argmax))];
  return std::min(needed_, -config_.significance_per_sample * static_cast<double>(n_));
}

bool ZoneGuide::claim(std::size_t index) {
  if (!restricted_ || !one_per_zone_) return true;
  const std::size_t z = static_cast<std::size_t>(zoneOf(index));
  if (used_[z]) return false;
  used_[z] = true;
  return true;
}

bool ZoneGuide::isPreferred(std::size_t anchor) const {
  return anchor < config_.preferred_anchors.size() && config_.preferred_anchors[anchor];
}

// The sensory event is independent evidence of a change, so an in-zone candidate may need less of
// ClaSP's own evidence (zone_p_value_threshold); a zone around a rest edge carries more evidence
// still (rest_edge_p_value_threshold).
void ZoneGuide::initNeededLog10P() {
  const double log10_threshold = std::log10(config_.clasp.p_value_threshold);
  needed_ = restricted_ && config_.zone_p_value_threshold > 0.0
                ? std::log10(config_.zone_p_value_threshold)
                : log10_threshold;
  zone_needed_.assign(zones_.size(), needed_);
  if (!(config_.rest_edge_p_value_threshold > 0.0)) return;
  for (std::size_t i = 0; i < config_.zone_anchors.size(); ++i) {
    const int z = zoneOf(config_.zone_anchors[i]);
    if (z >= 0 && isPreferred(i))
      zone_needed_[static_cast<std::size_t>(z)] =
          std::max(needed_, std::log10(config_.rest_edge_p_value_threshold));
  }
}

}  // namespace lfd
