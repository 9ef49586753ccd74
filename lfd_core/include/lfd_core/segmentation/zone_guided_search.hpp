// The zone-guided search of multivariate ClaSP (segmentMultivariate with candidate_zones or
// candidate_zones_for, and zone_anchors): which samples may be candidates, where a candidate is
// placed, and what significance it needs. Without zones every sample may be a candidate and
// ClaSP's own test (with significance_per_sample) decides.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "lfd_core/segmentation/multivariate_segmentation.hpp"
#include "lfd_core/segmentation/sensory_events.hpp"

namespace lfd {

/// Without anchors a zone marks one sensory interaction, hence at most one changepoint: once a
/// zone holds a changepoint it is closed to later candidates. With anchors each changepoint sits
/// on its own event, and zones closer than min_s merged into one can hold several interactions (a
/// short push: contact and release 2 s apart); the recursion's min_s margins keep their
/// changepoints apart. `config` must outlive the guide.
class ZoneGuide {
 public:
  /// The zones at min_s (candidate_zones_for) or the fixed ones; n = the series' length.
  ZoneGuide(const MultivariateSegmentationConfig& config, std::size_t min_s, std::size_t n);

  /// Candidates are restricted to zones (an empty zone list from candidate_zones_for: none).
  bool restricted() const { return restricted_; }

  /// The zone holding sample t; -1 = none.
  int zoneOf(std::size_t t) const;

  /// May t be a candidate: anywhere without zones, else in a zone still open.
  bool open(std::size_t t) const;

  /// Zones the range [begin, end) cannot split in: with anchors a zone is searched only while it
  /// holds an event ClaSP may split at (inside the range and its min_s margins, i.e. where
  /// `penalized` is defined); its others sit on changepoints already.
  std::vector<bool> closedZones(std::size_t begin, std::size_t end,
                                const Eigen::VectorXd& penalized) const;

  /// The anchor (sensory event) of t's zone nearest to t, preferred anchors (rest edges) first,
  /// relative to `begin` as t is; -1 = none.
  Eigen::Index anchorFor(const Eigen::VectorXd& profile, std::size_t begin, Eigen::Index t) const;

  /// The log10 p a candidate with its profile argmax at `argmax` needs.
  double neededLog10P(std::size_t argmax) const;

  /// Takes the zone of an accepted changepoint; false when one per zone and it was taken
  /// meanwhile (by a better candidate of another range).
  bool claim(std::size_t index);

 private:
  bool isPreferred(std::size_t anchor) const;
  void initNeededLog10P();

  const MultivariateSegmentationConfig& config_;
  const std::vector<Interval> zones_;
  const bool restricted_;
  const bool one_per_zone_;
  std::vector<bool> used_;
  const std::size_t n_;
  double needed_ = 0.0;              ///< outside zones, or in a zone without a rest edge
  std::vector<double> zone_needed_;  ///< per zone
};

}  // namespace lfd
