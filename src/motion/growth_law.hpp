// Lubachevsky–Stillinger growth of body sizes: every body is scaled about its centre by the
// common factor s(t) = s0 + rate (min(t, t_stop) - t0), linear until t_stop and constant after
// (docs/growth.md). A growing body is a rigid motion plus this outward motion of its surface.
#pragma once
#include <algorithm>

#include "math/types.hpp"

namespace hb {

struct GrowthLaw {
  double s0 = 1.0;
  double rate = 0.0;  // ds/dt (>= 0)
  double t0 = 0.0;
  double t_stop = kInf;

  double scale_at(double t) const { return s0 + rate * (std::min(t, t_stop) - t0); }
  double rate_at(double t) const { return t < t_stop ? rate : 0.0; }
  double final_scale() const { return t_stop == kInf ? kInf : scale_at(t_stop); }
  bool growing() const { return rate != 0.0; }
};

}  // namespace hb
