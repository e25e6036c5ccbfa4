// Approximations for inner loops where libm's exactness costs more than it gives.
#pragma once

#include <algorithm>
#include <cmath>

namespace hglasm {

/// Largest error of fastAtan2, radians (Abramowitz & Stegun 4.4.49): callers that bound a search by an angle
/// widen the bound by twice this, so the approximation never narrows it.
constexpr double kFastAtan2Error = 1.0e-5;

/// atan2(y, x) within kFastAtan2Error, 0 at the origin; branch-free, so loops over it vectorise.
template <typename Real>
inline Real fastAtan2(Real y, Real x) {
  const Real ax = std::abs(x), ay = std::abs(y);
  const Real big = std::max(ax, ay);
  const Real z = std::min(ax, ay) / (big > Real(0) ? big : Real(1));
  const Real z2 = z * z;
  Real angle =
      z * (Real(0.9998660) +
           z2 * (Real(-0.3302995) + z2 * (Real(0.1801410) + z2 * (Real(-0.0851330) + z2 * Real(0.0208351)))));
  angle = ay > ax ? Real(M_PI_2) - angle : angle;
  angle = x < Real(0) ? Real(M_PI) - angle : angle;
  return y < Real(0) ? -angle : angle;
}

}  // namespace hglasm
