// A shape placed in some frame: centre r and rotation R (body -> frame, columns = body axes).
// All derivatives are with respect to the frame coordinates:
//   f(x) = f_body(R^T (x - r)),  grad = R grad_body,  Hessian = R H_body R^T.
#pragma once
#include "math/types.hpp"
#include "shapes/shape.hpp"

namespace hb {

// Position and orientation of a body: x_frame = r + R x_body.
struct Pose {
  Vec3 r = Vec3::Zero();
  Mat3 R = Mat3::Identity();
};

// Pose of b expressed in the body frame of a.
inline Pose relative_pose(const Pose& a, const Pose& b) {
  return Pose{a.R.transpose() * (b.r - a.r), a.R.transpose() * b.R};
}

template <Shape S>
struct Posed {
  const S* shape;
  Pose pose;

  Vec3 to_body(const Vec3& x) const { return pose.R.transpose() * (x - pose.r); }
  Vec3 to_frame(const Vec3& y) const { return pose.r + pose.R * y; }
  double f(const Vec3& x) const { return shape->f(to_body(x)); }
  Vec3 grad(const Vec3& x) const { return pose.R * shape->grad(to_body(x)); }
  Mat3 hessian(const Vec3& x) const {
    return pose.R * shape->hessian(to_body(x)) * pose.R.transpose();
  }
  // f, gradient and Hessian in one transformation.
  void eval(const Vec3& x, double& fx, Vec3& g, Mat3& h) const {
    const Vec3 y = to_body(x);
    fx = shape->f(y);
    g = pose.R * shape->grad(y);
    h = pose.R * shape->hessian(y) * pose.R.transpose();
  }
  // Surface point on the ray from the centre along the frame direction u.
  Vec3 ray_surface(const Vec3& u) const {
    return to_frame(shape->ray_surface(pose.R.transpose() * u));
  }
};

template <Shape S>
Posed<S> posed(const S& s, const Pose& p) { return Posed<S>{&s, p}; }

}  // namespace hb
