// Consensus across the demonstrations of one task (segmentation_consensus.hpp).
#include "lfd_core/segmentation/segmentation_consensus.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

namespace lfd {
namespace {

std::string demoContext(std::size_t d) {
  return "demonstration " + std::to_string(d);
}

// The changepoint count the voting demos agree on: the most common count, held by at least 3 demos
// and by more demos than any other count; 0 = no agreement. With sensor validation only demos
// with evidence vote: a demo without any sensory event had no zone, so its count of 0 says
// nothing about the task (a dead sensor, a missed contact).
struct Agreement {
  std::size_t count = 0, votes = 0, voters = 0;
};

Agreement agreedCount(const SegmentationPipelineResult& result, bool validated) {
  std::map<std::size_t, std::size_t> votes;  // changepoint count -> demos
  Agreement a;
  for (const DemoSegmentationResult& d : result.demos) {
    if (validated && d.events.empty()) continue;
    ++votes[d.changepoints.size()];
    ++a.voters;
  }
  std::size_t runner_up = 0;
  for (const auto& [count, n] : votes) {
    if (n > a.votes) {
      runner_up = a.votes;
      a = {count, n, a.voters};
    } else {
      runner_up = std::max(runner_up, n);
    }
  }
  // A count that most demos found 0 of says nothing about where the boundaries are: the
  // changepoints of the other demos each stand on a sensory event of their own.
  if (a.votes < 3 || a.votes == runner_up || a.count == 0) a.count = 0;
  return a;
}

double log10POf(const DemoSegmentationResult& d, std::size_t cp) {
  for (const SplitCandidate& c : d.clasp.candidates)
    if (c.accepted && c.index == cp) return c.log10_p_value;
  return 0.0;
}

// A demo with more changepoints than agreed keeps its `k` most significant.
void pruneTo(std::size_t k, const FeatureMatrix& demo, DemoSegmentationResult* out,
             std::ostringstream* msg) {
  std::vector<std::pair<double, std::size_t>> by_p;  // (log10 p, changepoint)
  for (std::size_t cp : out->changepoints) by_p.emplace_back(log10POf(*out, cp), cp);
  std::stable_sort(by_p.begin(), by_p.end());
  *msg << "; dropped the least significant:";
  out->changepoints.clear();
  for (std::size_t i = 0; i < by_p.size(); ++i) {
    if (i < k) {
      out->changepoints.push_back(by_p[i].second);
      continue;
    }
    out->pruned.push_back(by_p[i].second);
    *msg << " t=" << demo.timeAt(by_p[i].second) << " (p=1e" << std::lround(by_p[i].first) << ")";
  }
}

// A demo with fewer changepoints than agreed takes, from the zones that hold none, ClaSP's
// best in-zone candidates that were not significant on their own but reach `log10_p` (the
// other demos' agreement is evidence too), most significant first. Only candidates of ranges
// that are still whole (no changepoint inside) count: the others were found before a split.
void fillTo(std::size_t k, double log10_p, const FeatureMatrix& demo, DemoSegmentationResult* out,
            std::ostringstream* msg) {
  std::vector<const SplitCandidate*> pool;
  for (const SplitCandidate& c : out->clasp.candidates) {
    if (c.accepted || c.log10_p_value > log10_p) continue;
    const bool whole =
        std::none_of(out->changepoints.begin(), out->changepoints.end(),
                     [&](std::size_t cp) { return c.range_begin < cp && cp < c.range_end; });
    if (whole) pool.push_back(&c);
  }
  std::stable_sort(pool.begin(), pool.end(), [](const SplitCandidate* a, const SplitCandidate* b) {
    return a->log10_p_value < b->log10_p_value;
  });
  const auto zone_of = [&](std::size_t t) -> int {
    for (std::size_t z = 0; z < out->zones.size(); ++z)
      if (out->zones[z].contains(t)) return static_cast<int>(z);
    return -1;
  };
  *msg << "; added the best in-zone candidates:";
  for (const SplitCandidate* c : pool) {
    if (out->changepoints.size() >= k) break;
    const int zone = zone_of(c->index);
    const bool taken = std::any_of(out->changepoints.begin(), out->changepoints.end(),
                                   [&](std::size_t cp) { return zone_of(cp) == zone; });
    const bool too_close =
        std::any_of(out->changepoints.begin(), out->changepoints.end(), [&](std::size_t cp) {
          return (cp > c->index ? cp - c->index : c->index - cp) < out->min_segment_length;
        });
    if (zone < 0 || taken || too_close) continue;
    out->changepoints.push_back(c->index);
    out->added.push_back(c->index);
    *msg << " t=" << demo.timeAt(c->index) << " (p=1e" << std::lround(c->log10_p_value) << ")";
  }
  std::sort(out->changepoints.begin(), out->changepoints.end());
  std::sort(out->added.begin(), out->added.end());
}

}  // namespace

void agreeOnChangepointCount(const std::vector<FeatureMatrix>& demos, bool validated, double fill_p,
                             SegmentationPipelineResult* result) {
  const Agreement a = agreedCount(*result, validated);
  if (a.count == 0) return;
  for (std::size_t d = 0; d < result->demos.size(); ++d) {
    DemoSegmentationResult& out = result->demos[d];
    const std::size_t had = out.changepoints.size();
    const bool can_fill = fill_p > 0.0 && validated && !out.events.empty();
    if (had == a.count || (had < a.count && !can_fill)) continue;
    std::ostringstream msg;
    msg << demoContext(d) << ": " << had << " changepoints where " << a.votes << " of the "
        << a.voters << " voting demonstrations have " << a.count;
    if (had > a.count)
      pruneTo(a.count, demos[d], &out, &msg);
    else
      fillTo(a.count, std::log10(fill_p), demos[d], &out, &msg);
    if (out.changepoints.size() == had && out.pruned.empty()) continue;  // nothing to add
    std::sort(out.changepoints.begin(), out.changepoints.end());
    std::sort(out.pruned.begin(), out.pruned.end());
    out.changepoint_times.clear();
    out.pruned_times.clear();
    out.added_times.clear();
    for (std::size_t cp : out.changepoints) out.changepoint_times.push_back(demos[d].timeAt(cp));
    for (std::size_t cp : out.pruned) out.pruned_times.push_back(demos[d].timeAt(cp));
    for (std::size_t cp : out.added) out.added_times.push_back(demos[d].timeAt(cp));
    result->warnings.push_back(msg.str());
  }
}

}  // namespace lfd
