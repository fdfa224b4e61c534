#include "omnivert/calib/model.hpp"

#include <algorithm>
#include <cmath>

#include "omnivert/core/angles.hpp"

namespace omnivert::calib {

Vec2 wheel_step(double d_right, double d_left, double wheel_base, Mat2* J_step_wheels) {
  // Eq. (15).
  if (J_step_wheels) *J_step_wheels << 0.5, 0.5, 1.0 / wheel_base, -1.0 / wheel_base;
  return {0.5 * (d_right + d_left), (d_right - d_left) / wheel_base};
}

Eigen::Vector3d integrate_pose(const Eigen::Vector3d& pose,
                               double d_right,
                               double d_left,
                               double wheel_base) {
  // Eq. (14): the heading at mid-step.
  const Vec2 s = wheel_step(d_right, d_left, wheel_base);
  const double mid = pose(2) + 0.5 * s(1);
  return {pose(0) + s(0) * std::cos(mid), pose(1) + s(0) * std::sin(mid), pose(2) + s(1)};
}

Eigen::Vector3d integrate_pose_lateral(
    const Eigen::Vector3d& pose, double d_right, double d_left, double lateral, double wheel_base) {
  Eigen::Vector3d p = integrate_pose(pose, d_right, d_left, wheel_base);
  const double mid = pose(2) + 0.5 * (d_right - d_left) / wheel_base;
  p(0) -= lateral * std::sin(mid);
  p(1) += lateral * std::cos(mid);
  return p;
}

namespace {
// compose_wheel_steps over sample steps (right, left).
Eigen::Vector3d compose_steps(const std::vector<Eigen::Vector2d>& steps, double wheel_base) {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  // in the robot frame of the first image
  for (const Eigen::Vector2d& d : steps) p = integrate_pose(p, d(0), d(1), wheel_base);
  const double mid = 0.5 * p(2), c = std::cos(mid), s = std::sin(mid);
  const double along = c * p(0) + s * p(1), lateral = -s * p(0) + c * p(1);
  return {along + 0.5 * wheel_base * p(2), along - 0.5 * wheel_base * p(2), lateral};
}
}  // namespace

Eigen::Vector3d compose_wheel_steps(const std::vector<Eigen::Vector2d>& travel,
                                    double wheel_base,
                                    Eigen::Matrix3d* covariance_per_K) {
  std::vector<Eigen::Vector2d> steps;  // (right, left) per sample step
  for (std::size_t i = 1; i < travel.size(); ++i)
    steps.emplace_back(travel[i](1) - travel[i - 1](1), travel[i](0) - travel[i - 1](0));
  const Eigen::Vector3d out = compose_steps(steps, wheel_base);
  if (covariance_per_K) {
    // First order: sum over steps and wheels of J J^T |d| (central differences; the map is
    // smooth and the steps millimetres, so h = 1e-7 m leaves errors near 1e-14).
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    constexpr double h = 1e-7;
    for (std::size_t i = 0; i < steps.size(); ++i)
      for (int w = 0; w < 2; ++w) {
        const double d = steps[i](w);
        if (d == 0.0) continue;
        std::vector<Eigen::Vector2d> a = steps, b = steps;
        a[i](w) += h;
        b[i](w) -= h;
        const Eigen::Vector3d J =
            (compose_steps(a, wheel_base) - compose_steps(b, wheel_base)) / (2 * h);
        C += std::abs(d) * J * J.transpose();
      }
    *covariance_per_K = C;
  }
  return out;
}

Vec2 propagate_feature(
    const Vec2& x, double d_right, double d_left, double wheel_base, Mat2* J_out_x, Mat2* J_out_u) {
  const double D = x(0), th = x(1);
  Mat2 J_step_wheels;
  const Vec2 s = wheel_step(d_right, d_left, wheel_base, &J_step_wheels);
  const double dr = s(0), dt = s(1);
  const double c = std::cos(th), sn = std::sin(th);
  // Eq. (29): D' = D + d_rho cos(theta), theta' = theta + d_theta - d_rho sin(theta) / D.
  const Vec2 out(D + dr * c, th + dt - dr * sn / D);
  if (J_out_x) {
    // A^i of appendix A.4.
    *J_out_x << 1.0, -dr * sn, dr * sn / (D * D), 1.0 - dr * c / D;
  }
  if (J_out_u) {
    // B^i of eq. (32), columns (d_R, d_L): d(out)/d(d_rho, d_theta) * eq. (15).
    Mat2 J_out_step;
    J_out_step << c, 0.0, -sn / D, 1.0;
    *J_out_u = J_out_step * J_step_wheels;
  }
  return out;
}

Vec2 propagate_feature_inverse(
    const Vec2& x, double d_right, double d_left, double wheel_base, Mat2* J_out_x, Mat2* J_out_u) {
  // Eq. (29) with q = 1/D: D' = D + d_rho cos(theta) gives q' = q / (1 + q d_rho cos(theta)),
  // and theta' = theta + d_theta - d_rho q sin(theta). Defined at q = 0 (feature at infinity).
  const double q = x(0), th = x(1);
  Mat2 J_step_wheels;
  const Vec2 s = wheel_step(d_right, d_left, wheel_base, &J_step_wheels);
  const double dr = s(0), dt = s(1);
  const double c = std::cos(th), sn = std::sin(th);
  const double den = 1.0 + q * dr * c;
  const Vec2 out(q / den, th + dt - dr * q * sn);
  if (J_out_x) {
    *J_out_x << 1.0 / (den * den), q * q * dr * sn / (den * den), -dr * sn, 1.0 - dr * q * c;
  }
  if (J_out_u) {
    Mat2 J_out_step;
    J_out_step << -q * q * c / (den * den), 0.0, -q * sn, 1.0;
    *J_out_u = J_out_step * J_step_wheels;
  }
  return out;
}

double predict_bearing(double D, double theta, const Extrinsics& ex, Row5* J_beta_x) {
  const double g = theta + ex.phi;
  const double c = std::cos(g), s = std::sin(g);
  // Eq. (27): beta = atan2(-rho sin(theta + phi), -D - rho cos(theta + phi)) - theta - phi - psi.
  const double beta =
      wrap_angle(std::atan2(-ex.rho * s, -D - ex.rho * c) - theta - ex.phi - ex.psi);
  if (J_beta_x) {
    // Appendix A.4: H1..H4 share the denominator D^2 + 2 rho D cos(theta + phi) + rho^2,
    // which is the squared camera-to-feature distance (> 0 while the camera is not on it).
    const double n = D * D + 2.0 * ex.rho * D * c + ex.rho * ex.rho;
    const double h1 = -ex.rho * s / n;
    const double h2 = (-D * ex.rho * c - D * D) / n;  // H3 = H2 (theta + phi appear together)
    const double h4 = D * s / n;
    *J_beta_x << h1, h2, h2, h4, -1.0;
  }
  return beta;
}

double predict_bearing_inverse(double q, double theta, const Extrinsics& ex, Row5* J_beta_x) {
  const double g = theta + ex.phi;
  const double c = std::cos(g), s = std::sin(g);
  // Eq. (27) multiplied inside the atan2 by q > 0: atan2(-rho q s, -1 - rho q c).
  const double rq = ex.rho * q;
  const double beta = wrap_angle(std::atan2(-rq * s, -1.0 - rq * c) - theta - ex.phi - ex.psi);
  if (J_beta_x) {
    const double n = 1.0 + 2.0 * rq * c + rq * rq;
    const double h_q = ex.rho * s / n;
    const double h_g = (rq * c + rq * rq) / n - 1.0;
    const double h_rho = q * s / n;
    *J_beta_x << h_q, h_g, h_g, h_rho, -1.0;
  }
  return beta;
}

double bearing_from_geometry(const Eigen::Vector3d& robot_pose,
                             const Vec2& feature,
                             const Extrinsics& ex) {
  const double a = robot_pose(2) + ex.phi;
  const double xc = robot_pose(0) + ex.rho * std::cos(a);
  const double yc = robot_pose(1) + ex.rho * std::sin(a);
  return wrap_angle(std::atan2(feature(1) - yc, feature(0) - xc) -
                    (robot_pose(2) + ex.phi + ex.psi));
}

Mat2 chong_kleeman_covariance(double d_right, double d_left, double K, double floor) {
  // Eq. (31): each wheel's true travel ~ N(d^e, K |d^e|), the two independent.
  Mat2 Q = Mat2::Zero();
  Q(0, 0) = K * std::abs(d_right) + floor;
  Q(1, 1) = K * std::abs(d_left) + floor;
  return Q;
}

Vec2 feature_from_ray(
    double q_c, double beta, const Extrinsics& ex, Mat2* J_out_in, Mat23* J_out_ex) {
  // Camera centre c = rho (cos phi, sin phi); ray direction u at gamma = beta + phi + psi in
  // the robot frame; the feature p = c + u / q_c; then D = |p| and, since the feature sits at
  // (-D cos theta, D sin theta) in the robot frame, theta = atan2(p_y, -p_x).
  const double gam = beta + ex.phi + ex.psi;
  const Vec2 u(std::cos(gam), std::sin(gam));
  const Vec2 u_perp(-u(1), u(0));
  const Vec2 cdir(std::cos(ex.phi), std::sin(ex.phi));
  const double r = 1.0 / q_c;
  const Vec2 p = ex.rho * cdir + r * u;
  const double D2 = p.squaredNorm();
  const double D = std::sqrt(D2);
  const Vec2 out(1.0 / D, std::atan2(p(1), -p(0)));
  if (J_out_in || J_out_ex) {
    Eigen::Matrix2d J_out_p;
    J_out_p.row(0) = -p.transpose() / (D2 * D);
    J_out_p.row(1) << p(1) / D2, -p(0) / D2;
    if (J_out_in) {
      Mat2 J_p_in;
      J_p_in.col(0) = -r * r * u;
      J_p_in.col(1) = r * u_perp;
      *J_out_in = J_out_p * J_p_in;
    }
    if (J_out_ex) {
      Mat23 J_p_ex;
      J_p_ex.col(0) = ex.rho * Vec2(-cdir(1), cdir(0)) + r * u_perp;
      J_p_ex.col(1) = cdir;
      J_p_ex.col(2) = r * u_perp;
      *J_out_ex = J_out_p * J_p_ex;
    }
  }
  return out;
}

Vec2 feature_to_world(const Eigen::Vector3d& robot_pose, double D, double theta) {
  // theta = theta_R - atan2(y_R - y_f, x_R - x_f): the feature-to-robot direction is
  // theta_R - theta, so f = R - D (cos(theta_R - theta), sin(theta_R - theta)).
  const double a = robot_pose(2) - theta;
  return {robot_pose(0) - D * std::cos(a), robot_pose(1) - D * std::sin(a)};
}

Vec2 feature_from_world(const Eigen::Vector3d& robot_pose, const Vec2& feature) {
  const double dx = robot_pose(0) - feature(0), dy = robot_pose(1) - feature(1);
  return {std::hypot(dx, dy), wrap_angle(robot_pose(2) - std::atan2(dy, dx))};
}

}  // namespace omnivert::calib

namespace omnivert::calib {

namespace {
// R(a) and dR/da = R(a) S with S = [0 -1; 1 0].
Mat2 rot(double a) {
  Mat2 R;
  R << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  return R;
}
const Mat2 kS = (Mat2() << 0, -1, 1, 0).finished();
}  // namespace

Vec2 propagate_point(
    const Vec2& p, double d_right, double d_left, double wheel_base, Mat2* J_out_p, Mat2* J_out_u) {
  Mat2 J_step_wheels;
  const Vec2 s = wheel_step(d_right, d_left, wheel_base, &J_step_wheels);
  const double dr = s(0), dt = s(1);
  const Vec2 h(std::cos(0.5 * dt), std::sin(0.5 * dt));
  const Vec2 t = dr * h;  // eq. (14): translation along the mid-step heading
  const Mat2 Rm = rot(-dt);
  const Vec2 out = Rm * (p - t);
  if (J_out_p) *J_out_p = Rm;
  if (J_out_u) {
    Mat2 J_out_step;
    J_out_step.col(0) = -Rm * h;
    J_out_step.col(1) = -Rm * kS * (p - t) - Rm * (0.5 * dr * kS * h);
    *J_out_u = J_out_step * J_step_wheels;
  }
  return out;
}

Vec4 propagate_anchored(const Vec4& f,
                        double d_right,
                        double d_left,
                        double wheel_base,
                        Mat4* J_out_f,
                        Mat42* J_out_u) {
  Mat2 Ja, Jua;
  Vec4 out;
  out.head<2>() = propagate_point(f.head<2>(), d_right, d_left, wheel_base, &Ja, &Jua);
  const double dt = (d_right - d_left) / wheel_base;  // eq. (15)
  out(2) = f(2) - dt;
  out(3) = f(3);
  if (J_out_f) {
    J_out_f->setIdentity();
    J_out_f->topLeftCorner<2, 2>() = Ja;
  }
  if (J_out_u) {
    J_out_u->setZero();
    J_out_u->topRows<2>() = Jua;
    J_out_u->row(2) << -1.0 / wheel_base, 1.0 / wheel_base;
  }
  return out;
}

double predict_bearing_point(const Vec2& p,
                             const Vec3& cam,
                             Eigen::Matrix<double, 1, 2>* J_beta_p,
                             Row3* J_beta_cam) {
  const Vec2 v = p - cam.head<2>();
  const double n2 = v.squaredNorm();
  const double beta = wrap_angle(std::atan2(v(1), v(0)) - cam(2));
  const Eigen::Matrix<double, 1, 2> J_v(-v(1) / n2, v(0) / n2);
  if (J_beta_p) *J_beta_p = J_v;
  if (J_beta_cam) *J_beta_cam << -J_v(0), -J_v(1), -1.0;
  return beta;
}

double predict_bearing_anchored(const Vec4& f, const Vec3& cam, Row4* J_beta_f, Row3* J_beta_cam) {
  const Vec2 ac = f.head<2>() - cam.head<2>();
  const Vec2 u(std::cos(f(2)), std::sin(f(2)));
  const Vec2 v = f(3) * ac + u;
  const double n2 = v.squaredNorm();
  const double beta = wrap_angle(std::atan2(v(1), v(0)) - cam(2));
  const Eigen::Matrix<double, 1, 2> J_v(-v(1) / n2, v(0) / n2);
  if (J_beta_f) {
    (*J_beta_f) << f(3) * J_v, J_v.dot(Vec2(-u(1), u(0))), J_v.dot(ac);
  }
  if (J_beta_cam) *J_beta_cam << -f(3) * J_v, -1.0;
  return beta;
}

Vec2 anchored_to_point(const Vec4& f, Eigen::Matrix<double, 2, 4>* J_p_f) {
  const Vec2 u(std::cos(f(2)), std::sin(f(2)));
  if (J_p_f) {
    J_p_f->leftCols<2>().setIdentity();
    J_p_f->col(2) = Vec2(-u(1), u(0)) / f(3);
    J_p_f->col(3) = -u / (f(3) * f(3));
  }
  return f.head<2>() + u / f(3);
}

Vec2 point_to_distance_form(const Vec2& p, Mat2* J_out_p) {
  // p = (-D cos theta, D sin theta): D = |p|, theta = atan2(p_y, -p_x).
  const double D2 = p.squaredNorm(), D = std::sqrt(D2);
  if (J_out_p) *J_out_p << p(0) / D, p(1) / D, p(1) / D2, -p(0) / D2;
  return {D, std::atan2(p(1), -p(0))};
}

Vec3 camera_pose_from_extrinsics(const Extrinsics& ex, Mat3* J_cam_ex) {
  const double c = std::cos(ex.phi), s = std::sin(ex.phi);
  if (J_cam_ex) *J_cam_ex << -ex.rho * s, c, 0, ex.rho * c, s, 0, 1, 0, 1;
  return {ex.rho * c, ex.rho * s, wrap_angle(ex.phi + ex.psi)};
}

Extrinsics extrinsics_from_camera_pose(const Vec3& cam, Mat3* J_ex_cam) {
  const double r2 = cam.head<2>().squaredNorm(), r = std::sqrt(r2);
  const double phi = std::atan2(cam(1), cam(0));
  if (J_ex_cam) {
    *J_ex_cam << -cam(1) / r2, cam(0) / r2, 0, cam(0) / r, cam(1) / r, 0, cam(1) / r2, -cam(0) / r2,
        1;
  }
  return {phi, r, wrap_angle(cam(2) - phi)};
}

std::set<int> crowded_directions(std::vector<std::pair<double, int>> v,
                                 double guard,
                                 const std::function<bool(int, int)>& same_line) {
  std::set<int> out;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t step = 1; step < n; ++step) {  // counter-clockwise until past the guard
      const std::size_t j = (i + step) % n;
      double d = v[j].first - v[i].first;
      if (j < i) d += kTwoPi;  // the circle closed
      if (!(d < guard)) break;
      if (same_line && same_line(v[i].second, v[j].second)) continue;
      out.insert(v[i].second);
      out.insert(v[j].second);
    }
  return out;
}

}  // namespace omnivert::calib
