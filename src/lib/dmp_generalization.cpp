#include "lfd_core/dmp_generalization.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

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

}  // namespace

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

GeneralizationResult generalizeSegment(const std::vector<SegmentDmp>& demos,
                                       const std::vector<Eigen::VectorXd>& params,
                                       const Eigen::VectorXd& query,
                                       const GeneralizationOptions& options) {
  if (demos.empty()) throw std::invalid_argument("generalizeSegment: no demonstrations");
  if (params.size() != demos.size()) {
    throw std::invalid_argument("generalizeSegment: " + std::to_string(demos.size()) +
                                " demos but " + std::to_string(params.size()) +
                                " parameter vectors");
  }
  const Eigen::Index dim = query.size();
  if (dim == 0) throw std::invalid_argument("generalizeSegment: empty query");
  requireFinite(query, "generalizeSegment query");
  if (!(options.bandwidth >= 0.0) || !(options.slope_ridge >= 0.0) ||
      !(options.range_margin >= 0.0)) {
    throw std::invalid_argument("generalizeSegment: bandwidth, slope_ridge, range_margin >= 0");
  }
  const size_t nd = demos.size();
  Eigen::MatrixXd points(dim, static_cast<Eigen::Index>(nd));
  for (size_t j = 0; j < nd; ++j) {
    checkCompatible(demos[0], demos[j], j);
    if (params[j].size() != dim) {
      throw std::invalid_argument("generalizeSegment: demo " + std::to_string(j) + " has " +
                                  std::to_string(params[j].size()) + " parameters, the query has " +
                                  std::to_string(dim));
    }
    requireFinite(params[j], "generalizeSegment demo parameters");
    points.col(static_cast<Eigen::Index>(j)) = params[j];
  }

  GeneralizationResult result;
  // Bandwidth and diameter from pairwise distances.
  std::vector<double> dists;
  for (size_t a = 0; a < nd; ++a) {
    for (size_t b = a + 1; b < nd; ++b) dists.push_back((params[a] - params[b]).norm());
  }
  double diameter = 0.0;
  for (double d : dists) diameter = std::max(diameter, d);
  double h = options.bandwidth;
  if (h <= 0.0) {
    if (!dists.empty()) {
      std::nth_element(dists.begin(), dists.begin() + dists.size() / 2, dists.end());
      h = dists[dists.size() / 2];
    }
    if (!(h > 0.0)) h = 1.0;  // a single (or repeated) demo: any bandwidth gives the same answer
  }
  result.bandwidth = h;

  // Kernel weights (shifted in the exponent so far queries do not underflow to all zeros).
  const Eigen::Index j_count = static_cast<Eigen::Index>(nd);
  Eigen::VectorXd sq(j_count);
  for (Eigen::Index j = 0; j < j_count; ++j)
    sq[j] = (points.col(j) - query).squaredNorm() / (h * h);
  const double min_sq = sq.minCoeff();
  Eigen::VectorXd k = (-0.5 * (sq.array() - min_sq)).exp().matrix();
  result.kernel_weights = k / k.sum();

  if (options.local_linear && nd > 1) {
    // Weighted least squares of y ~ b0 + b^T (p - q) / h with a ridge on b; the prediction is
    // b0 = sum_j c_j y_j with c = K X (X^T K X + L)^-1 e1.
    Eigen::MatrixXd x(j_count, dim + 1);
    x.col(0).setOnes();
    for (Eigen::Index j = 0; j < j_count; ++j) {
      x.block(j, 1, 1, dim) = ((points.col(j) - query) / h).transpose();
    }
    Eigen::MatrixXd m = x.transpose() * k.asDiagonal() * x;
    const double lambda = std::max(options.slope_ridge, 1e-12) * k.sum();
    for (Eigen::Index i = 1; i <= dim; ++i) m(i, i) += lambda;
    const Eigen::VectorXd e1 = Eigen::VectorXd::Unit(dim + 1, 0);
    const Eigen::VectorXd sol = m.ldlt().solve(e1);
    result.coefficients = k.asDiagonal() * (x * sol);
    // Exact affine combination despite round-off.
    result.coefficients /= result.coefficients.sum();
  } else {
    result.coefficients = result.kernel_weights;
  }
  const Eigen::VectorXd& c = result.coefficients;
  const Eigen::VectorXd& kw = result.kernel_weights;

  // Combine the demos.
  const SegmentDmp& ref = demos[0];
  SegmentDmp& out = result.dmp;
  out.params = ref.params;
  out.tau = 0.0;
  for (size_t j = 0; j < nd; ++j) out.tau += kw[static_cast<Eigen::Index>(j)] * demos[j].tau;
  if (ref.position) {
    Eigen::MatrixXd w = Eigen::MatrixXd::Zero(ref.position->weights().rows(), ref.position->dims());
    Eigen::VectorXd s = Eigen::VectorXd::Zero(ref.position->dims()), g = s, v = s;
    for (size_t j = 0; j < nd; ++j) {
      const PositionDmp& p = *demos[j].position;
      const double cj = c[static_cast<Eigen::Index>(j)];
      w += cj * p.weights();
      s += cj * p.start();
      g += cj * p.goal();
      v += cj * p.startVelocity() * (demos[j].tau / out.tau);  // keep v = tau * dy/dt consistent
    }
    out.position.emplace(ref.params, out.tau, w, s, g, v);
  }
  if (ref.orientation) {
    Eigen::MatrixXd w = Eigen::MatrixXd::Zero(ref.orientation->weights().rows(), 3);
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    std::vector<Eigen::Quaterniond> starts, goals;
    for (size_t j = 0; j < nd; ++j) {
      const OrientationDmp& o = *demos[j].orientation;
      const double cj = c[static_cast<Eigen::Index>(j)];
      w += cj * o.weights();
      v += cj * o.startAngularVelocity() * (demos[j].tau / out.tau);
      starts.push_back(o.start());
      goals.push_back(o.goal());
    }
    out.orientation.emplace(ref.params, out.tau, w, weightedQuaternionMean(starts, kw),
                            weightedQuaternionMean(goals, kw), v);
  }
  if (ref.gripper) {
    // The gripper, whole (levels, forcing weights, start velocity), is a convex average: its shape
    // does not follow the goal linearly (the reason for the local linear fit), and the DMP being
    // linear in all four, the mix is then a convex mix of the demos' gripper motions, which cannot
    // open where no demo opens. An affine mix turned one demo's closing into an opening.
    Eigen::MatrixXd w = Eigen::MatrixXd::Zero(ref.gripper->weights().rows(), 1);
    Eigen::VectorXd s = Eigen::VectorXd::Zero(1), g = s, v = s;
    for (size_t j = 0; j < nd; ++j) {
      const PositionDmp& p = *demos[j].gripper;
      const double kj = kw[static_cast<Eigen::Index>(j)];
      w += kj * p.weights();
      s += kj * p.start();
      g += kj * p.goal();
      v += kj * p.startVelocity() * (demos[j].tau / out.tau);
    }
    out.gripper.emplace(ref.params, out.tau, w, s, g, v);
  }

  // Coverage check.
  result.hull_distance = convexHullDistance(points, query);
  result.margin = std::max(options.range_margin * diameter, 1e-9);
  result.outside_demo_range = result.hull_distance > result.margin;
  if (result.outside_demo_range) {
    std::ostringstream msg;
    msg << "query lies " << result.hull_distance
        << " outside the convex hull of the demonstrated parameters (allowed margin "
        << result.margin << "); the DMP is extrapolated";
    result.warning = msg.str();
  }
  return result;
}

}  // namespace lfd
