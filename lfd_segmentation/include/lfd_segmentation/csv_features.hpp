// CSV -> feature matrix for the `segment` CLI: a header row names the columns, one row per
// sample, comma separated. An optional time column (seconds) becomes the clock; `rate` > 0 Hz
// overrides it with uniformly spaced samples; with neither the matrix has no clock.
#pragma once

#include <string>

#include "lfd_core/segmentation/time_series.hpp"
#include "lfd_segmentation/segmentation_params.hpp"

namespace lfd_segmentation {

/// `time_column`: a column name, or "" to use a column named time, t, timestamp or stamp when
/// present. Throws std::invalid_argument (file, line and column named) for an unreadable file,
/// a missing header, ragged rows, unparsable cells or a missing time column that was asked for.
/// NaN/Inf cells are kept so that the pipeline can report them by feature. Over `limits` (feature
/// columns, checked on the header; data rows; finite |values| whose squares would overflow the
/// distances) the read stops at once with the limit's key, the line and the column. A UTF-8
/// byte-order mark is skipped; a UTF-16 file is refused ("save it as UTF-8").
lfd::FeatureMatrix readCsvFeatures(const std::string& path, const std::string& time_column = "",
                                   double rate = 0.0,
                                   const RequestLimits& limits = RequestLimits());

/// "" for a clock without gaps; else a warning naming the largest gap: the segmentation takes the
/// rows as evenly spaced (its windows and lags are counted in samples of the median step), so a
/// gap of more than `max_missing` median steps shifts every time parameter across it.
std::string clockGapWarning(const lfd::FeatureMatrix& matrix, const std::string& path,
                            double max_missing = 10.0);

}  // namespace lfd_segmentation
