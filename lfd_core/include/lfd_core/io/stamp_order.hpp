// The one timestamp policy of every reader of recorded messages (the segmentation's bag reader,
// the learner's demo reader): messages are taken in the order of their stamps, never of their
// arrival; out-of-order and duplicate stamps are counted, and so are gaps, and each reader passes
// the warning on. Nothing is dropped silently (the learner skipped every pose
// stamped before one 5 s late message, 48% of a demo, while the segmentation sorted the same bag).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace lfd {

/// A step between consecutive stamps longer than this many typical (median) steps is a gap: a
/// recorder stall or lost messages (10: a 100 Hz stream missing 0.1 s; jitter stays below 3).
constexpr double kStampGapFactor = 10.0;

/// What ordering one stream's stamps found.
struct StampReport {
  std::size_t messages = 0;
  std::size_t out_of_order = 0;  ///< stamped before a message that arrived earlier
  std::size_t duplicates = 0;    ///< stamped the same as another message
  std::size_t dropped = 0;       ///< duplicates left out (unique stamps asked for)
  double typical_step = 0.0;     ///< median step between ordered stamps (s)
  double largest_gap = 0.0;      ///< longest step over kStampGapFactor typical steps (0 = none)
  double gap_start = 0.0;        ///< stamp where that gap begins (s)
};

/// What a reader does with messages that share a stamp: keep them all (a resampler averages
/// them), or keep the first of each stamp (a DMP needs strictly increasing times); either way
/// they are counted.
enum class DuplicateStamps { kKeepAll, kKeepFirst };

/// The indices of `stamps` in stamp order (stable: equal stamps keep their arrival order), with
/// later duplicates left out under kKeepFirst. Fills `report` when given.
std::vector<std::size_t> orderByStamp(const std::vector<double>& stamps, DuplicateStamps duplicates,
                                      StampReport* report = nullptr);

/// The warning for `report` naming `topic` and the counts, or "" when the stamps were in order,
/// unique and without gaps.
std::string stampWarning(const std::string& topic, const StampReport& report);

}  // namespace lfd
