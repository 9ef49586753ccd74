// Multivariate time series on one clock: named feature columns + timestamps, resampling of
// streams recorded at different rates, normalization and finiteness checks.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace lfd {

/// How a stream is evaluated between its samples when resampling.
enum class Interpolation {
  kLinear,         ///< continuous signals (poses, velocities, forces)
  kZeroOrderHold,  ///< discrete signals (flags, commands): hold the last value
};

/// One recorded signal: sample times (s, non-decreasing) and values.
struct Stream {
  std::string name;
  std::vector<double> time;
  std::vector<double> values;
  Interpolation interpolation = Interpolation::kLinear;
};

/// Samples (rows) x named features (columns) on a common clock. Column-major storage keeps each
/// feature contiguous, which is what DTW and ClaSP read.
struct FeatureMatrix {
  std::vector<double> time;        ///< one timestamp per row (s); may be empty = implicit index
  std::vector<std::string> names;  ///< one name per column
  Eigen::MatrixXd data;            ///< rows() samples x cols() features

  Eigen::Index rows() const { return data.rows(); }
  Eigen::Index cols() const { return data.cols(); }
  /// Column index of a feature, or -1.
  int indexOf(const std::string& name) const;
  /// Column index of a feature; throws std::invalid_argument naming the missing feature.
  int require(const std::string& name) const;
  /// Time of a row: the stored timestamp, or the row index when no clock is stored.
  double timeAt(Eigen::Index row) const;
  /// timeAt of every row.
  std::vector<double> clock() const;
  /// The sub-matrix of the listed features (in that order); throws if one is missing.
  FeatureMatrix select(const std::vector<std::string>& features) const;
  /// Throws std::invalid_argument if the shape is inconsistent (names/time vs data).
  void validateShape() const;
};

/// Resamples streams onto one uniform clock at `rate_hz`, spanning the interval where every
/// stream has data (latest start .. earliest end). A continuous stream sampled faster than the
/// clock is averaged over each clock sample's period (centred on it), otherwise interpolated;
/// a discrete (zero-order-hold) stream holds its last value. Throws std::invalid_argument on empty
/// or non-finite streams, decreasing timestamps, or streams that do not overlap in time.
FeatureMatrix resample(const std::vector<Stream>& streams, double rate_hz);

/// The same for the columns of a matrix on its own clock (every column continuous): a CSV
/// recorded faster than the segmentation needs (a 1 kHz F/T) averaged onto `rate_hz`. Throws
/// std::invalid_argument when the matrix has no clock.
FeatureMatrix resample(const FeatureMatrix& matrix, double rate_hz);

/// Evaluates one stream at the given query times (queries outside the stream are clamped).
std::vector<double> interpolate(const Stream& stream, const std::vector<double>& query_times);

/// Result of normalizing a matrix column-wise.
struct NormalizationInfo {
  std::vector<double> offset;  ///< subtracted per column (min or mean)
  std::vector<double> scale;   ///< divided by per column (range or std); 1 for constant columns
  std::vector<bool> constant;  ///< column had (numerically) no variation -> set to 0
};

/// Max-min normalization of each column to [0,1]. A constant column (range <= eps * (1+|max|))
/// becomes all zeros and is flagged rather than producing NaN.
NormalizationInfo normalizeMinMax(Eigen::MatrixXd& data, double eps = 1e-12);
/// Zero mean, unit standard deviation per column; constant columns become 0 and are flagged.
NormalizationInfo zNormalize(Eigen::MatrixXd& data, double eps = 1e-12);

/// Same as above on a single signal; returns true when the signal was constant.
bool normalizeMinMax(Eigen::Ref<Eigen::VectorXd> signal, double eps = 1e-12);

/// Throws std::invalid_argument naming the first NaN/Inf sample (feature, row and time).
void checkFinite(const FeatureMatrix& matrix, const std::string& context = "");

}  // namespace lfd
