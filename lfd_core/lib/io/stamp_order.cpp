#include "lfd_core/io/stamp_order.hpp"

#include <algorithm>
#include <numeric>
#include <sstream>

namespace lfd {
namespace {

// Messages that had to move: all but the longest run already in stamp order (not every message
// after one stamped late, which would count half a demo for a single late message).
std::size_t countOutOfOrder(const std::vector<double>& stamps) {
  std::vector<double> tails;  // tails[k]: least last stamp of an in-order run of k + 1 messages
  for (double t : stamps) {
    const auto it = std::upper_bound(tails.begin(), tails.end(), t);
    if (it == tails.end()) {
      tails.push_back(t);
    } else {
      *it = t;
    }
  }
  return stamps.size() - tails.size();
}

// Median step and the longest gap of stamps already in order.
void findGaps(const std::vector<double>& ordered, StampReport* report) {
  if (ordered.size() < 3) return;
  std::vector<double> steps;
  for (std::size_t i = 1; i < ordered.size(); ++i) steps.push_back(ordered[i] - ordered[i - 1]);
  std::vector<double> sorted = steps;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  report->typical_step = sorted[sorted.size() / 2];
  if (!(report->typical_step > 0)) return;  // mostly duplicates: no clock to judge gaps by
  for (std::size_t i = 0; i < steps.size(); ++i) {
    if (steps[i] > kStampGapFactor * report->typical_step && steps[i] > report->largest_gap) {
      report->largest_gap = steps[i];
      report->gap_start = ordered[i];
    }
  }
}

}  // namespace

std::vector<std::size_t> orderByStamp(const std::vector<double>& stamps, DuplicateStamps duplicates,
                                      StampReport* report) {
  std::vector<std::size_t> order(stamps.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return stamps[a] < stamps[b]; });
  StampReport r;
  r.messages = stamps.size();
  r.out_of_order = countOutOfOrder(stamps);
  std::vector<std::size_t> kept;
  kept.reserve(order.size());
  for (std::size_t i : order) {
    const bool duplicate = !kept.empty() && stamps[i] == stamps[kept.back()];
    if (duplicate) ++r.duplicates;
    if (duplicate && duplicates == DuplicateStamps::kKeepFirst) {
      ++r.dropped;
      continue;
    }
    kept.push_back(i);
  }
  std::vector<double> ordered;
  ordered.reserve(kept.size());
  for (std::size_t i : kept) ordered.push_back(stamps[i]);
  findGaps(ordered, &r);
  if (report) *report = r;
  return kept;
}

std::string stampWarning(const std::string& topic, const StampReport& r) {
  if (r.out_of_order == 0 && r.duplicates == 0 && r.largest_gap == 0) return "";
  std::ostringstream out;
  out << topic << ": of " << r.messages << " messages";
  if (r.out_of_order > 0) out << ", " << r.out_of_order << " stamped out of order (put in order)";
  if (r.duplicates > 0) {
    out << ", " << r.duplicates << " with a duplicate stamp ("
        << (r.dropped > 0 ? "the first of each kept" : "all kept") << ")";
  }
  if (r.largest_gap > 0) {
    out << ", a gap of " << r.largest_gap << " s at t = " << r.gap_start << " (typical step "
        << r.typical_step << " s)";
  }
  return out.str();
}

}  // namespace lfd
