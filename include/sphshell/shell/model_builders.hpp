#pragma once
// The builders of the usual shapes, ShellModel's static members (declared
// with their contracts in shell/model.hpp, which includes this file).

#include <sphshell/shell/model.hpp>

namespace sphshell {

inline ShellModel ShellModel::rectangular_plate(double length_x, double length_y, int nx, int ny, double thickness) {
  detail::require_positive("length_x", length_x);
  detail::require_positive("length_y", length_y);
  detail::model_checks::require_count("nx", nx, 2);
  detail::model_checks::require_count("ny", ny, 2);
  detail::model_checks::require_grid_size("nx × ny", static_cast<long long>(nx) * ny);
  auto surface = [&](double u, double v) {
    return std::make_pair(Vector3(u * length_x, v * length_y, 0.0), Vector3(0.0, 0.0, 1.0));
  };
  ShellModel model = structured(nx, ny, false, surface, thickness);
  const double tolerance = 1e-9 * std::max(length_x, length_y);
  model.define_set("x_min", [&](const Vector3& x) { return x.x() < tolerance; });
  model.define_set("x_max", [&](const Vector3& x) { return x.x() > length_x - tolerance; });
  model.define_set("y_min", [&](const Vector3& x) { return x.y() < tolerance; });
  model.define_set("y_max", [&](const Vector3& x) { return x.y() > length_y - tolerance; });
  model.define_set("boundary", [&](const Vector3& x) {
    return x.x() < tolerance || x.x() > length_x - tolerance || x.y() < tolerance || x.y() > length_y - tolerance;
  });
  model.sets_["centre"] = {model.nearest_particle(Vector3(length_x / 2, length_y / 2, 0.0))};
  return model;
}

inline ShellModel ShellModel::cylindrical_panel(double radius, double length, double angle, int n_circumferential,
                                                int n_axial, double thickness) {
  detail::require_positive("radius", radius);
  detail::require_positive("length", length);
  if (!(angle > 0.0 && angle <= 2.0 * kPi + 1e-12)) detail::invalid_parameter("angle", angle, "must lie in (0, 2π]");
  const bool closed = angle > 2.0 * kPi - 1e-12;
  detail::model_checks::require_count("n_circumferential", n_circumferential, closed ? 3 : 2);
  detail::model_checks::require_count("n_axial", n_axial, 2);
  detail::model_checks::require_grid_size("n_circumferential × n_axial",
                                          static_cast<long long>(n_circumferential) * n_axial);
  auto surface = [&](double u, double v) {
    const double theta = u * angle;
    const Vector3 normal(std::cos(theta), std::sin(theta), 0.0);
    return std::make_pair(Vector3(radius * normal.x(), radius * normal.y(), v * length), normal);
  };
  ShellModel model = structured(n_circumferential, n_axial, closed, surface, thickness);
  const double tolerance = 1e-9 * std::max(radius, length);
  model.define_set("z_min", [&](const Vector3& x) { return x.z() < tolerance; });
  model.define_set("z_max", [&](const Vector3& x) { return x.z() > length - tolerance; });
  if (!closed) {
    const int n = n_circumferential;
    ParticleSet first, last;
    for (int j = 0; j < n_axial; ++j) {
      first.push_back(j * n);
      last.push_back(j * n + n - 1);
    }
    model.sets_["theta_min"] = first;
    model.sets_["theta_max"] = last;
  }
  return model;
}

inline ShellModel ShellModel::spherical_cap(double radius, double half_angle, int n, double thickness) {
  detail::require_positive("radius", radius);
  if (!(half_angle > 0.0 && half_angle < kPi / 2))
    detail::invalid_parameter("half_angle", half_angle, "must lie in (0, π/2)");
  detail::model_checks::require_count("n", n, 3);
  detail::model_checks::require_grid_size("n × n", static_cast<long long>(n) * n);
  auto surface = [&](double u, double v) {
    const double s = 2.0 * u - 1.0;
    const double t = 2.0 * v - 1.0;
    const double disc_x = s * std::sqrt(1.0 - t * t / 2.0);
    const double disc_y = t * std::sqrt(1.0 - s * s / 2.0);
    const double disc_radius = std::min(1.0, std::hypot(disc_x, disc_y));
    const double polar = disc_radius * half_angle;
    const double azimuth = std::atan2(disc_y, disc_x);
    const Vector3 normal(std::sin(polar) * std::cos(azimuth), std::sin(polar) * std::sin(azimuth), std::cos(polar));
    return std::make_pair(Vector3(radius * normal), normal);
  };
  ShellModel model = structured(n, n, false, surface, thickness);
  ParticleSet rim;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      if (i == 0 || j == 0 || i == n - 1 || j == n - 1) rim.push_back(j * n + i);
  model.sets_["boundary"] = rim;
  model.sets_["apex"] = {model.nearest_particle(Vector3(0.0, 0.0, radius))};
  return model;
}

template <class Surface>
ShellModel ShellModel::structured(int nu, int nv, bool periodic_u, Surface&& surface, double thickness) {
  const int columns = periodic_u ? nu : nu - 1;
  // Counted before anything is allocated: a grid too large is an Error with its size.
  const double particles = static_cast<double>(nu) * nv, cells = static_cast<double>(columns) * (nv - 1);
  const std::string grid = "the grid of " + std::to_string(nu) + " x " + std::to_string(nv) + " particles";
  const double estimate = detail::model_checks::require_model_memory(grid, particles, cells);
  return detail::model_checks::guard_building(grid, estimate, [&] {
    std::vector<Vector3> positions, normals;
    auto u_of = [&](double i) { return i / columns; };
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) {
        auto point = surface(u_of(i), static_cast<double>(j) / (nv - 1));
        positions.push_back(point.first);
        normals.push_back(point.second);
      }
    std::vector<Quad> quads;
    std::vector<Vector3> centres, centre_normals;
    for (int j = 0; j + 1 < nv; ++j)
      for (int i = 0; i < columns; ++i) {
        const int next = (i + 1) % nu;
        quads.push_back({j * nu + i, j * nu + next, (j + 1) * nu + next, (j + 1) * nu + i});
        auto centre = surface(u_of(i + 0.5), (j + 0.5) / (nv - 1));
        centres.push_back(centre.first);
        centre_normals.push_back(centre.second);
      }
    return from_quads(std::move(positions), std::move(normals), quads, std::move(centres), std::move(centre_normals),
                      thickness);
  });
}

}  // namespace sphshell
