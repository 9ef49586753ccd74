#include "lfd_core/dmp/dmp_generalization.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace lfd {
namespace {

// Euclidean projection onto the probability simplex (sort-based, Duchi et al. 2008).
Eigen::VectorXd projectToSimplex(const Eigen::VectorXd& v) {
  std::vector<double> u(v.data(), v.data() + v.size());
  std::sort(u.begin(), u.end(), std::greater<double>());
  double cumsum = 0.0, theta = 0.0;
  for (size_t i = 0; i < u.size(); ++i) {
    cumsum += u[i];
    const double t = (cumsum - 1.0) / static_cast<double>(i + 1);
    if (u[i] - t > 0.0) theta = t;
  }
  return (v.array() - theta).max(0.0).matrix();
}

void checkCompatible(const SegmentDmp& ref, const SegmentDmp& d, size_t index) {
  auto fail = [&](const std::string& why) {
    throw std::invalid_argument("generalizeSegment: demo " + std::to_string(index) + " " + why);
  };
  d.validate();
  if (d.params.num_basis != ref.params.num_basis || d.params.alpha_x != ref.params.alpha_x ||
      d.params.width_scale != ref.params.width_scale || d.params.alpha_z != ref.params.alpha_z ||
      d.params.beta_z != ref.params.beta_z) {
    fail("has different DMP parameters than demo 0");
  }
  if (d.position.has_value() != ref.position.has_value() ||
      d.orientation.has_value() != ref.orientation.has_value() ||
      d.gripper.has_value() != ref.gripper.has_value()) {
    fail("has different parts (position/orientation/gripper) than demo 0");
  }
  if (d.position && d.position->dims() != ref.position->dims()) {
    fail("has a different position dimension than demo 0");
  }
}

Eigen::Quaterniond weightedQuaternionMean(const std::vector<Eigen::Quaterniond>& qs,
                                          const Eigen::VectorXd& w) {
  // Hemisphere-aligned weighted sum: accurate for the nearby orientations of one segment.
  Eigen::Vector4d acc = Eigen::Vector4d::Zero();
  for (size_t j = 0; j < qs.size(); ++j) {
    Eigen::Vector4d c = qs[j].coeffs();
    if (c.dot(qs[0].coeffs()) < 0.0) c = -c;
    acc += w[static_cast<Eigen::Index>(j)] * c;
  }
  if (acc.norm() < 1e-12) return qs[0];
  acc.normalize();
  return Eigen::Quaterniond(acc[3], acc[0], acc[1], acc[2]);
}

// Normalized Gaussian kernel weights of the columns of `points` at `query` (shifted in the exponent
// so that far queries do not underflow to all zeros).
Eigen::VectorXd kernelWeights(const Eigen::MatrixXd& points, const Eigen::VectorXd& query,
                              double h) {
  Eigen::VectorXd sq(points.cols());
  for (Eigen::Index j = 0; j < points.cols(); ++j)
    sq[j] = (points.col(j) - query).squaredNorm() / (h * h);
  const Eigen::VectorXd k = (-0.5 * (sq.array() - sq.minCoeff())).exp().matrix();
  return k / k.sum();
}

// Weighted least squares of y ~ b0 + b^T (p - q) / h with a ridge on b; the prediction is
// b0 = sum_j c_j y_j with c = K X (X^T K X + L)^-1 e1: an affine combination (sums to 1).
Eigen::VectorXd localLinearCoefficients(const Eigen::MatrixXd& points, const Eigen::VectorXd& query,
                                        double h, const Eigen::VectorXd& k, double ridge) {
  const Eigen::Index dim = query.size(), j_count = points.cols();
  Eigen::MatrixXd x(j_count, dim + 1);
  x.col(0).setOnes();
  for (Eigen::Index j = 0; j < j_count; ++j)
    x.block(j, 1, 1, dim) = ((points.col(j) - query) / h).transpose();
  Eigen::MatrixXd m = x.transpose() * k.asDiagonal() * x;
  const double lambda = std::max(ridge, 1e-12) * k.sum();
  for (Eigen::Index i = 1; i <= dim; ++i) m(i, i) += lambda;
  const Eigen::VectorXd sol = m.ldlt().solve(Eigen::VectorXd::Unit(dim + 1, 0));
  Eigen::VectorXd c = k.asDiagonal() * (x * sol);
  return c / c.sum();  // exact affine combination despite round-off
}

Eigen::MatrixXd parameterMatrix(const std::vector<Eigen::VectorXd>& params) {
  Eigen::MatrixXd points(params.front().size(), static_cast<Eigen::Index>(params.size()));
  for (size_t j = 0; j < params.size(); ++j) points.col(static_cast<Eigen::Index>(j)) = params[j];
  return points;
}

// Samples of a leave-one-out rollout: enough for a segment's shape, cheap for a few demos.
constexpr int kLooSamples = 200;

// Position RMS between demo `held`'s own rollout and the rollout of the forcing weights mixed
// from the other demos by `c` (indexed like `others`), both over the held demo's start, goal,
// start velocity and duration.
double heldOutRms(const PositionDmp& held, const std::vector<const PositionDmp*>& others,
                  const Eigen::VectorXd& c) {
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(held.weights().rows(), held.dims());
  for (size_t i = 0; i < others.size(); ++i)
    w += c[static_cast<Eigen::Index>(i)] * others[i]->weights();
  const PositionDmp mixed(held.parameters(), held.tau(), w, held.start(), held.goal(),
                          held.startVelocity());
  const double dt = held.tau() / (kLooSamples - 1);
  Eigen::MatrixXd own(kLooSamples, held.dims()), predicted(kLooSamples, held.dims());
  const double* v = held.startVelocity().data();
  held.rolloutInto(held.start().data(), held.goal().data(), v, held.tau(), dt, kLooSamples,
                   own.data());
  mixed.rolloutInto(held.start().data(), held.goal().data(), v, held.tau(), dt, kLooSamples,
                    predicted.data());
  return std::sqrt((own - predicted).rowwise().squaredNorm().mean());
}

// Each demo held out in turn: its position RMS (see leaveOneOutRms).
std::vector<double> leaveOneOutErrors(const std::vector<SegmentDmp>& demos,
                                      const std::vector<Eigen::VectorXd>& params, double bandwidth,
                                      double slope_ridge) {
  const bool positions =
      std::all_of(demos.begin(), demos.end(), [](const SegmentDmp& d) { return d.position; });
  if (demos.size() < 3 || params.size() != demos.size() || !(bandwidth > 0.0) || !positions)
    throw std::invalid_argument(
        "leaveOneOutRms: needs >= 3 demos with a position DMP, one parameter vector each, and a "
        "bandwidth > 0");
  std::vector<double> errors;
  for (size_t held = 0; held < demos.size(); ++held) {
    std::vector<Eigen::VectorXd> rest;
    std::vector<const PositionDmp*> others;
    for (size_t j = 0; j < demos.size(); ++j) {
      if (j == held) continue;
      rest.push_back(params[j]);
      others.push_back(&*demos[j].position);
    }
    const Eigen::MatrixXd points = parameterMatrix(rest);
    const Eigen::VectorXd k = kernelWeights(points, params[held], bandwidth);
    const Eigen::VectorXd c =
        localLinearCoefficients(points, params[held], bandwidth, k, slope_ridge);
    errors.push_back(heldOutRms(*demos[held].position, others, c));
  }
  return errors;
}
}  // namespace

double leaveOneOutRms(const std::vector<SegmentDmp>& demos,
                      const std::vector<Eigen::VectorXd>& params, double bandwidth,
                      double slope_ridge) {
  const std::vector<double> e = leaveOneOutErrors(demos, params, bandwidth, slope_ridge);
  return std::accumulate(e.begin(), e.end(), 0.0) / static_cast<double>(e.size());
}

Eigen::VectorXd goalParameters(const SegmentDmp& dmp) {
  if (!dmp.position) throw std::invalid_argument("goalParameters: the segment has no position DMP");
  return dmp.position->goal();
}

double convexHullDistance(const Eigen::MatrixXd& points, const Eigen::VectorXd& q) {
  const Eigen::Index j = points.cols();
  if (j == 0) throw std::invalid_argument("convexHullDistance: no points");
  if (j == 1) return (points.col(0) - q).norm();
  // minimize |P l - q|^2 over the simplex; Lipschitz constant of the gradient: 2 |P|_2^2.
  const Eigen::MatrixXd gram = points.transpose() * points;
  const double lipschitz =
      2.0 * std::max(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(gram).eigenvalues().maxCoeff(),
                     1e-300);
  Eigen::VectorXd l = Eigen::VectorXd::Constant(j, 1.0 / static_cast<double>(j));
  Eigen::VectorXd y = l;
  double t = 1.0;
  for (int it = 0; it < 5000; ++it) {  // FISTA
    const Eigen::VectorXd grad = 2.0 * points.transpose() * (points * y - q);
    const Eigen::VectorXd l_next = projectToSimplex(y - grad / lipschitz);
    const double t_next = 0.5 * (1.0 + std::sqrt(1.0 + 4.0 * t * t));
    y = l_next + ((t - 1.0) / t_next) * (l_next - l);
    if ((l_next - l).norm() < 1e-14) {
      l = l_next;
      break;
    }
    l = l_next;
    t = t_next;
  }
  return (points * l - q).norm();
}

namespace {

// options.slope_ridge, or by leave-one-out with the one-standard-error rule (Hastie, Tibshirani &
// Friedman, ESL 7.10): the largest ridge (the smoothest fit, nearest the convex kernel average)
// whose mean error is within one standard error of the best mean. With the 5-10 demos of a task
// the errors are noisy, and the plain minimum followed the noise. Writes each mean to *loo.
double chooseSlopeRidge(const std::vector<SegmentDmp>& demos,
                        const std::vector<Eigen::VectorXd>& params, double h,
                        const GeneralizationOptions& options, std::vector<double>* loo) {
  if (options.slope_ridge_candidates.size() < 2 || demos.size() < 3 || !demos.front().position)
    return options.slope_ridge;
  double best_mean = std::numeric_limits<double>::infinity(), best_se = 0.0;
  for (double ridge : options.slope_ridge_candidates) {
    const std::vector<double> e = leaveOneOutErrors(demos, params, h, ridge);
    const double n = static_cast<double>(e.size());
    const double mean = std::accumulate(e.begin(), e.end(), 0.0) / n;
    loo->push_back(mean);
    if (mean >= best_mean) continue;
    double var = 0.0;
    for (double x : e) var += (x - mean) * (x - mean);
    best_mean = mean;
    best_se = std::sqrt(var / (n - 1.0) / n);
  }
  double chosen = -1.0;
  for (size_t i = 0; i < loo->size(); ++i)
    if ((*loo)[i] <= best_mean + best_se)
      chosen = std::max(chosen, options.slope_ridge_candidates[i]);
  return chosen;
}

void checkInputs(const std::vector<SegmentDmp>& demos, const std::vector<Eigen::VectorXd>& params,
                 const Eigen::VectorXd& query, const GeneralizationOptions& options) {
  if (demos.empty()) throw std::invalid_argument("generalizeSegment: no demonstrations");
  if (params.size() != demos.size()) {
    throw std::invalid_argument("generalizeSegment: " + std::to_string(demos.size()) +
                                " demos but " + std::to_string(params.size()) +
                                " parameter vectors");
  }
  if (query.size() == 0) throw std::invalid_argument("generalizeSegment: empty query");
  requireFinite(query, "generalizeSegment query");
  bool ridges_ok = options.slope_ridge >= 0.0;
  for (double r : options.slope_ridge_candidates)
    ridges_ok = ridges_ok && r >= 0.0 && std::isfinite(r);
  if (!(options.bandwidth >= 0.0) || !ridges_ok || !(options.range_margin >= 0.0)) {
    throw std::invalid_argument(
        "generalizeSegment: bandwidth, slope_ridge (and its candidates), range_margin >= 0");
  }
  for (size_t j = 0; j < demos.size(); ++j) {
    checkCompatible(demos[0], demos[j], j);
    if (params[j].size() != query.size()) {
      throw std::invalid_argument("generalizeSegment: demo " + std::to_string(j) + " has " +
                                  std::to_string(params[j].size()) + " parameters, the query has " +
                                  std::to_string(query.size()));
    }
    requireFinite(params[j], "generalizeSegment demo parameters");
  }
}

// The kernel bandwidth (the option, else the median pairwise distance) and the demos' diameter.
std::pair<double, double> bandwidthAndDiameter(const std::vector<Eigen::VectorXd>& params,
                                               double bandwidth) {
  std::vector<double> dists;
  for (size_t a = 0; a < params.size(); ++a) {
    for (size_t b = a + 1; b < params.size(); ++b) dists.push_back((params[a] - params[b]).norm());
  }
  double diameter = 0.0;
  for (double d : dists) diameter = std::max(diameter, d);
  double h = bandwidth;
  if (h <= 0.0) {
    if (!dists.empty()) {
      std::nth_element(dists.begin(), dists.begin() + dists.size() / 2, dists.end());
      h = dists[dists.size() / 2];
    }
    if (!(h > 0.0)) h = 1.0;  // a single (or repeated) demo: any bandwidth gives the same answer
  }
  return {h, diameter};
}

// The demos' position-like DMPs (the position, or the gripper) mixed with `coefficients`.
PositionDmp mixPositionDmps(const std::vector<SegmentDmp>& demos,
                            const std::optional<PositionDmp> SegmentDmp::*which,
                            const Eigen::VectorXd& coefficients, double tau) {
  const PositionDmp& ref = *(demos[0].*which);
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(ref.weights().rows(), ref.dims());
  Eigen::VectorXd s = Eigen::VectorXd::Zero(ref.dims()), g = s, v = s;
  for (size_t j = 0; j < demos.size(); ++j) {
    const PositionDmp& p = *(demos[j].*which);
    const double cj = coefficients[static_cast<Eigen::Index>(j)];
    w += cj * p.weights();
    s += cj * p.start();
    g += cj * p.goal();
    v += cj * p.startVelocity() * (demos[j].tau / tau);  // keep v = tau * dy/dt consistent
  }
  return PositionDmp(demos[0].params, tau, w, s, g, v);
}

OrientationDmp mixOrientationDmps(const std::vector<SegmentDmp>& demos,
                                  const Eigen::VectorXd& coefficients,
                                  const Eigen::VectorXd& kernel_weights, double tau) {
  Eigen::MatrixXd w = Eigen::MatrixXd::Zero(demos[0].orientation->weights().rows(), 3);
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  std::vector<Eigen::Quaterniond> starts, goals;
  for (size_t j = 0; j < demos.size(); ++j) {
    const OrientationDmp& o = *demos[j].orientation;
    const double cj = coefficients[static_cast<Eigen::Index>(j)];
    w += cj * o.weights();
    v += cj * o.startAngularVelocity() * (demos[j].tau / tau);
    starts.push_back(o.start());
    goals.push_back(o.goal());
  }
  return OrientationDmp(demos[0].params, tau, w, weightedQuaternionMean(starts, kernel_weights),
                        weightedQuaternionMean(goals, kernel_weights), v);
}

void checkCoverage(const Eigen::MatrixXd& points, const Eigen::VectorXd& query, double diameter,
                   double range_margin, GeneralizationResult& result) {
  result.hull_distance = convexHullDistance(points, query);
  result.margin = std::max(range_margin * diameter, 1e-9);
  result.outside_demo_range = result.hull_distance > result.margin;
  if (result.outside_demo_range) {
    std::ostringstream msg;
    msg << "query lies " << result.hull_distance
        << " outside the convex hull of the demonstrated parameters (allowed margin "
        << result.margin << "); the DMP is extrapolated";
    result.warning = msg.str();
  }
}

}  // namespace

GeneralizationResult generalizeSegment(const std::vector<SegmentDmp>& demos,
                                       const std::vector<Eigen::VectorXd>& params,
                                       const Eigen::VectorXd& query,
                                       const GeneralizationOptions& options) {
  checkInputs(demos, params, query, options);
  const size_t nd = demos.size();
  const Eigen::MatrixXd points = parameterMatrix(params);
  GeneralizationResult result;
  const auto [h, diameter] = bandwidthAndDiameter(params, options.bandwidth);
  result.bandwidth = h;
  result.kernel_weights = kernelWeights(points, query, h);
  if (options.local_linear && nd > 1) {
    result.slope_ridge = chooseSlopeRidge(demos, params, h, options, &result.loo_rms);
    result.coefficients =
        localLinearCoefficients(points, query, h, result.kernel_weights, result.slope_ridge);
  } else {
    result.coefficients = result.kernel_weights;
  }
  const Eigen::VectorXd& kw = result.kernel_weights;
  SegmentDmp& out = result.dmp;
  out.params = demos[0].params;
  out.tau = 0.0;
  for (size_t j = 0; j < nd; ++j) out.tau += kw[static_cast<Eigen::Index>(j)] * demos[j].tau;
  if (demos[0].position)
    out.position = mixPositionDmps(demos, &SegmentDmp::position, result.coefficients, out.tau);
  if (demos[0].orientation)
    out.orientation = mixOrientationDmps(demos, result.coefficients, kw, out.tau);
  // The gripper, whole (levels, forcing weights, start velocity), is a convex average: its shape
  // does not follow the goal linearly (the reason for the local linear fit), and the DMP being
  // linear in all four, the mix is then a convex mix of the demos' gripper motions, which cannot
  // open where no demo opens. An affine mix turned one demo's closing into an opening.
  if (demos[0].gripper) out.gripper = mixPositionDmps(demos, &SegmentDmp::gripper, kw, out.tau);
  checkCoverage(points, query, diameter, options.range_margin, result);
  return result;
}

}  // namespace lfd
