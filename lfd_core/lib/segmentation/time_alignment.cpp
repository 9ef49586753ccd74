#include "lfd_core/segmentation/time_alignment.hpp"

#include "lfd_core/segmentation/smooth_derivatives.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace lfd {
namespace {

constexpr int kYawCandidates = 8;  // coarse yaws tried before the fit (45 deg apart)

// Linear interpolation of the rows of `values` (sampled at increasing `x`) at `q`, clamped.
Eigen::RowVectorXd interpolateRow(const Eigen::VectorXd& x, const Eigen::MatrixXd& values,
                                  double q) {
  const Eigen::Index n = x.size();
  if (q <= x[0]) return values.row(0);
  if (q >= x[n - 1]) return values.row(n - 1);
  const Eigen::Index i = std::upper_bound(x.data(), x.data() + n, q) - x.data();
  const double a = (q - x[i - 1]) / (x[i] - x[i - 1]);
  return (1.0 - a) * values.row(i - 1) + a * values.row(i);
}

double interpolate(const Eigen::VectorXd& x, const Eigen::VectorXd& y, double q) {
  return interpolateRow(x, y, q)[0];
}

// The quaternion rows (w, x, y, z) at time q: normalized linear interpolation on the shorter arc
// (neighbouring samples are close, so this is slerp to ~1e-6).
Eigen::RowVectorXd interpolateQuaternion(const Eigen::VectorXd& t, const Eigen::MatrixXd& quats,
                                         double q) {
  const Eigen::Index n = t.size();
  const Eigen::Index i =
      std::clamp<Eigen::Index>(std::upper_bound(t.data(), t.data() + n, q) - t.data(), 1, n - 1);
  const double a = std::clamp((q - t[i - 1]) / (t[i] - t[i - 1]), 0.0, 1.0);
  Eigen::RowVectorXd b = quats.row(i);
  if (b.dot(quats.row(i - 1)) < 0.0) b = -b;
  Eigen::RowVectorXd r = (1.0 - a) * quats.row(i - 1) + a * b;
  return r / r.norm();
}

// What DTW compares of a demo: its hand position and, when recorded, its gripper opening (a
// distance too), relative to their start and resampled every `step` s (at least 2 samples), in
// units of the path's length (the hand's and the gripper's travel). The gripper is what moves
// while the hand holds still (a grasp, a release): without it, DTW could place the closing of one
// demo after the lift of another. In units of the length because demos of one segment go
// different distances (to objects nearer or farther), and DTW on the raw paths would re-time one
// to make its positions meet the other's.
Eigen::MatrixXd comparedPath(const SegmentDemo& d, double step) {
  const double t0 = d.times[0], duration = d.times[d.times.size() - 1] - t0;
  const int n = std::max(2, static_cast<int>(std::lround(duration / step)) + 1);
  const Eigen::Index dp = d.positions.cols(), dg = d.gripper.size() > 0 ? 1 : 0;
  Eigen::MatrixXd out(n, dp + dg);
  for (int i = 0; i < n; ++i) {
    const double t = t0 + duration * i / (n - 1.0);
    out.row(i).head(dp) = interpolateRow(d.times, d.positions, t);
    if (dg) out(i, dp) = interpolate(d.times, d.gripper, t);
  }
  out.rowwise() -= out.row(0).eval();
  double length = 0.0;
  for (int i = 1; i < n; ++i) length += (out.row(i) - out.row(i - 1)).norm();
  if (length > 0.0) out /= length;
  return out;
}

Eigen::MatrixXd turned(const Eigen::MatrixXd& path, double yaw) {
  if (yaw == 0.0) return path;
  Eigen::MatrixXd out = path;
  const double c = std::cos(yaw), s = std::sin(yaw);
  out.col(0) = c * path.col(0) - s * path.col(1);
  out.col(1) = s * path.col(0) + c * path.col(1);
  return out;
}

// The yaw that best turns b's matched points onto a's (2-D Procrustes on the horizontal part).
double fittedYaw(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                 const std::vector<std::pair<int, int>>& path) {
  double sin_sum = 0.0, cos_sum = 0.0;
  for (const auto& [i, j] : path) {
    sin_sum += b(j, 0) * a(i, 1) - b(j, 1) * a(i, 0);
    cos_sum += b(j, 0) * a(i, 0) + b(j, 1) * a(i, 1);
  }
  return std::atan2(sin_sum, cos_sum);
}

struct Match {
  double cost = 0.0;  // DTW cost per compared sample (lengths differ)
  double yaw = 0.0;   // turns b onto a
};

// How well b matches a: DTW, over the yaws about z when asked (a coarse search, then the yaw
// fitted on the matched samples: a sample-by-sample fit alone can be fooled by strokes at
// different times, which match a forward stroke to a return).
Match compare(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, bool yaw_invariant) {
  // yaw_invariant: the first three columns are a 3-D position (the caller checks)
  const double norm = static_cast<double>(a.rows() + b.rows());
  Match best{dtwRows(a, b) / norm, 0.0};
  if (!yaw_invariant) return best;
  for (int k = 1; k < kYawCandidates; ++k) {
    const double yaw = 2.0 * M_PI * k / kYawCandidates;
    const double cost = dtwRows(a, turned(b, yaw)) / norm;
    if (cost < best.cost) best = {cost, yaw};
  }
  std::vector<std::pair<int, int>> path;
  dtwRows(a, turned(b, best.yaw), &path);
  const double yaw = fittedYaw(a, b, path);
  const double cost = dtwRows(a, turned(b, yaw)) / norm;
  if (cost < best.cost) best = {cost, yaw};
  return best;
}

// The demo with the least summed DTW cost to the others.
std::size_t medoid(const std::vector<Eigen::MatrixXd>& paths, bool yaw_invariant) {
  const std::size_t n = paths.size();
  std::vector<double> sum(n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const double c = compare(paths[i], paths[j], yaw_invariant).cost;
      sum[i] += c;
      sum[j] += c;
    }
  return static_cast<std::size_t>(std::min_element(sum.begin(), sum.end()) - sum.begin());
}

// Gaussian smoothing (sigma in samples) of a warp from 0 to 1, reflected oddly about both ends
// (w(-u) = -w(u), w(1 + u) = 2 - w(1 - u)): the ends stay at 0 and 1, a line stays a line, and a
// jump at an end (below) becomes a ramp instead of being cancelled by a one-sided mean.
Eigen::VectorXd smoothWarp(const Eigen::VectorXd& warp, double sigma) {
  const Eigen::Index n = warp.size();
  const Eigen::Index pad = std::min<Eigen::Index>(n - 1, std::lround(std::ceil(4.0 * sigma)));
  Eigen::VectorXd padded(n + 2 * pad);
  for (Eigen::Index k = 0; k < pad; ++k) {
    padded[pad - 1 - k] = -warp[k + 1];
    padded[pad + n + k] = 2.0 - warp[n - 2 - k];
  }
  padded.segment(pad, n) = warp;
  const Eigen::VectorXd clock = Eigen::VectorXd::LinSpaced(padded.size(), 0.0, padded.size() - 1.0);
  return gaussianSmooth(clock, padded, sigma).col(0).segment(pad, n);
}

// A demo's progress at each sample of the reference's grid, from the DTW path: the mean of the
// demo samples matched to it, smoothed (`sigma` in reference samples), monotone, from 0 to 1.
// The ends are set, not averaged: a demo that pauses where the other starts (or stops) moving
// matches its whole pause to the reference's first (last) sample, and their mean would cancel
// the pause.
Eigen::VectorXd warpFromPath(const std::vector<std::pair<int, int>>& path, Eigen::Index n_ref,
                             Eigen::Index n_demo, double sigma) {
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(n_ref), count = sum;
  for (const auto& [i, j] : path) {
    sum[i] += static_cast<double>(j) / static_cast<double>(n_demo - 1);
    count[i] += 1.0;
  }
  Eigen::VectorXd warp = sum.cwiseQuotient(count);
  warp[0] = 0.0;
  warp[n_ref - 1] = 1.0;
  if (sigma > 0.0 && n_ref > 2) warp = smoothWarp(warp, sigma);
  warp[0] = 0.0;
  warp[n_ref - 1] = 1.0;
  for (Eigen::Index i = 1; i < n_ref; ++i) warp[i] = std::max(warp[i], warp[i - 1]);
  return warp.cwiseMax(0.0).cwiseMin(1.0);
}

// The demo resampled at its own time stamps, each taking the pose it had at progress `source`.
SegmentDemo resampled(const SegmentDemo& d, const Eigen::VectorXd& source) {
  const Eigen::Index m = d.times.size();
  const double t0 = d.times[0], duration = d.times[m - 1] - t0;
  SegmentDemo out = d;
  for (Eigen::Index k = 0; k < m; ++k) {
    const double s = k == 0 ? t0 : k == m - 1 ? d.times[m - 1] : t0 + duration * source[k];
    if (d.positions.cols() > 0) out.positions.row(k) = interpolateRow(d.times, d.positions, s);
    if (d.quaternions.cols() == 4)
      out.quaternions.row(k) = interpolateQuaternion(d.times, d.quaternions, s);
    if (d.gripper.size() > 0) out.gripper[k] = interpolate(d.times, d.gripper, s);
  }
  return out;
}

void checkInput(const std::vector<SegmentDemo>& demos, const TimeAlignmentOptions& o) {
  checkTimeAlignmentOptions(o, "alignDemoTiming: ");
  for (std::size_t j = 0; j < demos.size(); ++j) {
    const SegmentDemo& d = demos[j];
    const std::string which = "alignDemoTiming: demo " + std::to_string(j);
    validateDemoTimes(d.times, which.c_str());
    if (d.positions.cols() != demos[0].positions.cols())
      throw std::invalid_argument(which + " has another position dimension than demo 0");
    if (d.positions.cols() > 0 && d.positions.rows() != d.times.size())
      throw std::invalid_argument(which + ": positions and times differ in length");
    if (d.quaternions.cols() > 0 &&
        (d.quaternions.cols() != 4 || d.quaternions.rows() != d.times.size()))
      throw std::invalid_argument(which + ": quaternions must be M x 4");
    if (d.gripper.size() > 0 && d.gripper.size() != d.times.size())
      throw std::invalid_argument(which + ": gripper and times differ in length");
    if ((d.gripper.size() > 0) != (demos[0].gripper.size() > 0))
      throw std::invalid_argument(which + (d.gripper.size() > 0 ? " has" : " has no") +
                                  " gripper, demo 0 the opposite");
    requireFinite(d.positions, which.c_str());
    requireFinite(d.gripper, which.c_str());
  }
}

}  // namespace

double dtwRows(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
               std::vector<std::pair<int, int>>* path, double band) {
  const Eigen::Index n = a.rows(), m = b.rows();
  if (n == 0 || m == 0 || a.cols() != b.cols())
    throw std::invalid_argument("dtwRows: empty series or different dimensions");
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // Row-major accumulated cost with a border of infinity: D(i+1, j+1) for cell (i, j).
  std::vector<double> acc(static_cast<std::size_t>((n + 1) * (m + 1)), kInf);
  auto at = [&](Eigen::Index i, Eigen::Index j) -> double& {
    return acc[static_cast<std::size_t>(i * (m + 1) + j)];
  };
  at(0, 0) = 0.0;
  // The slanted band: cell (i, j) within `radius` of the line joining the corners (at least one
  // cell, so the corner stays reachable).
  const double slope = n > 1 ? static_cast<double>(m - 1) / static_cast<double>(n - 1) : 0.0;
  const double radius = std::max(1.0, band * static_cast<double>(std::max(n, m)));
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < m; ++j) {
      if (band < 1.0 && std::abs(static_cast<double>(j) - slope * static_cast<double>(i)) > radius)
        continue;
      const double c = (a.row(i) - b.row(j)).squaredNorm();
      at(i + 1, j + 1) = c + std::min({at(i, j), at(i, j + 1), at(i + 1, j)});
    }
  if (path) {  // backtrack; ties prefer the diagonal, then "up" (a advances), as lfd::dtw
    path->clear();
    Eigen::Index i = n, j = m;
    while (i > 0 && j > 0) {
      path->emplace_back(static_cast<int>(i - 1), static_cast<int>(j - 1));
      const double diag = at(i - 1, j - 1), up = at(i - 1, j), left = at(i, j - 1);
      if (diag <= up && diag <= left) {
        --i;
        --j;
      } else if (up <= left) {
        --i;
      } else {
        --j;
      }
    }
    std::reverse(path->begin(), path->end());
  }
  return at(n, m);
}

void checkTimeAlignmentOptions(const TimeAlignmentOptions& o, const std::string& where) {
  if (!(o.sample_seconds > 0.0) || !std::isfinite(o.sample_seconds))
    throw std::invalid_argument(where + "sample_seconds must be finite and > 0 (s)");
  if (!(o.warp_sigma >= 0.0) || !std::isfinite(o.warp_sigma))
    throw std::invalid_argument(where + "warp_sigma must be finite and >= 0 (s)");
}

TimeAlignment alignDemoTiming(const std::vector<SegmentDemo>& demos,
                              const TimeAlignmentOptions& options) {
  checkInput(demos, options);
  TimeAlignment out;
  out.demos = demos;
  out.yaw.assign(demos.size(), 0.0);
  const Eigen::Index grid = 101;  // the progress grid the warps are reported on
  out.progress = Eigen::VectorXd::LinSpaced(grid, 0.0, 1.0);
  out.warps.assign(demos.size(), out.progress);
  if (demos.size() < 2 || demos[0].positions.cols() == 0) return out;

  std::vector<Eigen::MatrixXd> paths;
  for (const SegmentDemo& d : demos) paths.push_back(comparedPath(d, options.sample_seconds));
  const bool turn = options.yaw_invariant && demos[0].positions.cols() == 3;
  const std::size_t r = medoid(paths, turn);
  out.reference = r;
  const Eigen::Index n_ref = paths[r].rows();
  const double ref_duration = demos[r].times[demos[r].times.size() - 1] - demos[r].times[0];
  const Eigen::VectorXd ref_progress = Eigen::VectorXd::LinSpaced(n_ref, 0.0, 1.0);

  // Each demo's progress at the reference's (phi_j), and their mean: the common timing (mu).
  std::vector<Eigen::VectorXd> warp(demos.size(), ref_progress);
  Eigen::VectorXd common = ref_progress;
  for (std::size_t j = 0; j < demos.size(); ++j) {
    if (j == r) continue;
    out.yaw[j] = compare(paths[r], paths[j], turn).yaw;
    std::vector<std::pair<int, int>> path;
    dtwRows(paths[r], turned(paths[j], out.yaw[j]), &path);
    warp[j] =
        warpFromPath(path, n_ref, paths[j].rows(), options.warp_sigma * (n_ref - 1) / ref_duration);
    common += warp[j];
  }
  common /= static_cast<double>(demos.size());  // strictly increasing: the identity is in it

  // Demo j at common progress v takes the pose it had at phi_j(mu^-1(v)).
  for (std::size_t j = 0; j < demos.size(); ++j) {
    const SegmentDemo& d = demos[j];
    const Eigen::Index m = d.times.size();
    const double t0 = d.times[0], duration = d.times[m - 1] - t0;
    auto source = [&](double v) {
      return interpolate(ref_progress, warp[j], interpolate(common, ref_progress, v));
    };
    Eigen::VectorXd own(m);
    for (Eigen::Index k = 0; k < m; ++k) own[k] = source((d.times[k] - t0) / duration);
    out.demos[j] = resampled(d, own);
    for (Eigen::Index i = 0; i < grid; ++i) out.warps[j][i] = source(out.progress[i]);
  }
  return out;
}

}  // namespace lfd
