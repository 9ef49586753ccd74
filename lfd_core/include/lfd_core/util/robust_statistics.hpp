// Robust statistics shared by the segmentation's detectors: a median and sigmas that outliers
// (a contact's spike, a reach's motion) do not move.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace lfd {

/// The median of v (the mean of the two middle values for an even count); 0 for an empty v.
double medianOf(std::vector<double> v);

/// Robust sigma of v: 1.4826 x the median absolute deviation about its median (the sigma of
/// Gaussian samples).
double robustSigma(std::vector<double> v);

/// The sigma of the white noise on a signal, from its second differences (robust, about zero):
/// a smooth motion's second differences are small against the noise's (variance 6 sigma^2), so
/// the estimate holds while the signal moves. 0 for fewer than 3 samples.
double measurementNoiseSigma(const Eigen::Ref<const Eigen::VectorXd>& signal);

}  // namespace lfd
