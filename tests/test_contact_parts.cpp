#include <sphshell/contact/all.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

using namespace sphshell;
using namespace sphshell::contact;

namespace {

constexpr double pi = 3.14159265358979323846;

// The cube [−a, a]³ as 12 triangles, counter-clockwise seen from outside.
TriangleSurfaceParameters cube_surface(double a) {
  TriangleSurfaceParameters cube;
  for (int corner = 0; corner < 8; ++corner)
    cube.vertices.emplace_back((corner & 1) ? a : -a, (corner & 2) ? a : -a, (corner & 4) ? a : -a);
  // Each face as a quad (p, q, r, s) counter-clockwise from outside.
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    cube.triangles.push_back({f[0], f[1], f[2]});
    cube.triangles.push_back({f[0], f[2], f[3]});
  }
  return cube;
}

// Signed distance to the box [−a, a]³, written independently of the library.
double box_signed_distance(const Vector3& p, double a) {
  const Vector3 q = p.cwiseAbs() - Vector3::Constant(a);
  const double outside = q.cwiseMax(0.0).norm();
  const double inside = std::min(std::max(q.x(), std::max(q.y(), q.z())), 0.0);
  return outside + inside;
}

// An icosahedron subdivided `levels` times, its vertices on the sphere of radius r.
TriangleSurfaceParameters icosphere(double r, int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vector3> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                            {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p.normalize();
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoints;
    auto midpoint = [&](int a, int b) {
      const std::pair<int, int> key{std::min(a, b), std::max(a, b)};
      const auto found = midpoints.find(key);
      if (found != midpoints.end()) return found->second;
      v.push_back((v[a] + v[b]).normalized());
      midpoints[key] = static_cast<int>(v.size()) - 1;
      return static_cast<int>(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> finer;
    for (const auto& tri : f) {
      const int ab = midpoint(tri[0], tri[1]), bc = midpoint(tri[1], tri[2]), ca = midpoint(tri[2], tri[0]);
      finer.push_back({tri[0], ab, ca});
      finer.push_back({tri[1], bc, ab});
      finer.push_back({tri[2], ca, bc});
      finer.push_back({ab, bc, ca});
    }
    f = std::move(finer);
  }
  // Outward: the right-hand normal along the centroid.
  for (auto& tri : f) {
    const Vector3 normal = (v[tri[1]] - v[tri[0]]).cross(v[tri[2]] - v[tri[0]]);
    if (normal.dot(v[tri[0]] + v[tri[1]] + v[tri[2]]) < 0.0) std::swap(tri[1], tri[2]);
  }
  for (auto& p : v) p *= r;
  return {v, f};
}

// A shell particle standing in as a point mass, stepped by the central
// difference in the test itself.
struct TestParticles {
  std::vector<Vector3> position, director, velocity, angular_velocity;
  std::vector<double> mass, thickness;
  ContactParticles view() const { return {position, director, velocity, angular_velocity, mass, thickness}; }
};

TestParticles one_particle(const Vector3& x, const Vector3& d, const Vector3& v, double m, double h) {
  return {{x}, {d}, {v}, {Vector3::Zero()}, {m}, {h}};
}

}  // namespace

TEST_CASE("contact: a plane's and a sphere's signed distances", "[contact]") {
  RigidKinematics wall_at;
  wall_at.position = Vector3(0, 0, 1);
  const RigidBody<Plane, Fixed> wall(Plane(Vector3(0, 0, 2)), Fixed{}, wall_at);
  SurfaceProximity q = wall.proximity(Vector3(1, 2, 3));
  CHECK(q.gap == Approx(2.0).epsilon(1e-14));
  CHECK((q.normal - Vector3::UnitZ()).norm() < 1e-14);
  CHECK((q.nearest - Vector3(1, 2, 1)).norm() < 1e-14);
  CHECK(wall.proximity(Vector3(5, -1, 0.25)).gap == Approx(-0.75).epsilon(1e-14));

  RigidKinematics ball_at;
  ball_at.position = Vector3(1, 1, 1);
  const RigidBody<Sphere, Fixed> ball(Sphere(2.0), Fixed{}, ball_at);
  q = ball.proximity(Vector3(1, 1, 4));
  CHECK(q.gap == Approx(1.0).epsilon(1e-14));
  CHECK((q.normal - Vector3::UnitZ()).norm() < 1e-14);
  CHECK((q.nearest - Vector3(1, 1, 3)).norm() < 1e-14);
  q = ball.proximity(Vector3(1, 1.3, 1.4));  // inside, 0.5 from the centre
  CHECK(q.gap == Approx(-1.5).epsilon(1e-14));
  CHECK((q.normal - Vector3(0, 0.6, 0.8)).norm() < 1e-14);
}

TEST_CASE("contact: a turned cylinder's signed distances on the mantle, the caps and the rim", "[contact]") {
  // Body axis z turned onto world x (a quarter turn about y).
  RigidKinematics at;
  at.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(pi / 2, Vector3::UnitY()));
  const double radius = 1.0, length = 4.0;
  const RigidBody<Cylinder, Fixed> flat(Cylinder({Vector3::UnitZ(), radius, length, CylinderEnds::flat}), Fixed{}, at);
  struct Expected {
    Vector3 point;
    double gap;
    Vector3 normal;
  };
  const Expected flat_cases[] = {
      {{3.0, 0.0, 0.0}, 1.0, {1, 0, 0}},          // beyond the +x cap
      {{-2.5, 0.3, 0.0}, 0.5, {-1, 0, 0}},        // beyond the −x cap
      {{2.3, 1.4, 0.0}, 0.5, {0.6, 0.8, 0}},      // beyond the rim
      {{0.0, 0.0, 1.5}, 0.5, {0, 0, 1}},          // outside the mantle
      {{1.9, 0.0, 0.0}, -0.1, {1, 0, 0}},         // inside, nearest the cap
      {{0.0, 0.8, 0.0}, -0.2, {0, 1, 0}},         // inside, nearest the mantle
      {{1.95, 0.0, -0.9}, -0.05, {1, 0, 0}},      // inside near the rim, the cap nearer
  };
  for (const auto& c : flat_cases) {
    const SurfaceProximity q = flat.proximity(c.point);
    INFO("point " << c.point.transpose());
    CHECK(q.gap == Approx(c.gap).margin(1e-12));
    CHECK((q.normal - c.normal).norm() < 1e-12);
    CHECK(std::abs(flat.proximity(q.nearest).gap) < 1e-12);
  }
  const RigidBody<Cylinder, Fixed> capsule(
      Cylinder({Vector3::UnitZ(), radius, length, CylinderEnds::hemispherical}), Fixed{}, at);
  const Expected capsule_cases[] = {
      {{3.5, 0.0, 0.0}, 0.5, {1, 0, 0}},     // on the axis beyond the +x end
      {{3.2, 1.6, 0.0}, 1.0, {0.6, 0.8, 0}}, // off the hemisphere's centre (2, 0, 0)
      {{0.5, 0.0, 1.5}, 0.5, {0, 0, 1}},     // outside the mantle
      {{-2.3, 0.4, 0.0}, -0.5, {-0.6, 0.8, 0}},  // inside the −x hemisphere
  };
  for (const auto& c : capsule_cases) {
    const SurfaceProximity q = capsule.proximity(c.point);
    INFO("point " << c.point.transpose());
    CHECK(q.gap == Approx(c.gap).margin(1e-12));
    CHECK((q.normal - c.normal).norm() < 1e-12);
  }
}

TEST_CASE("contact: a triangulated cube's signed distance is the box's", "[contact]") {
  const double a = 1.0;
  const TriangleSurface cube(cube_surface(a));
  CHECK(cube.volume() == Approx(8.0).epsilon(1e-14));
  SurfaceProximity q = cube.proximity(Vector3(2, 2, 2));  // nearest a corner
  CHECK(q.gap == Approx(std::sqrt(3.0)).epsilon(1e-14));
  CHECK((q.normal - Vector3(1, 1, 1).normalized()).norm() < 1e-14);
  q = cube.proximity(Vector3(0.5, 0.2, 0.9));  // inside, nearest the top face
  CHECK(q.gap == Approx(-0.1).epsilon(1e-12));
  CHECK((q.normal - Vector3::UnitZ()).norm() < 1e-12);
  // Against the independent box distance everywhere around, edges and corners included.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-2.0, 2.0);
  for (int k = 0; k < 2000; ++k) {
    const Vector3 p(coordinate(random), coordinate(random), coordinate(random));
    INFO("point " << p.transpose());
    REQUIRE(cube.proximity(p).gap == Approx(box_signed_distance(p, a)).margin(1e-12));
  }
}

TEST_CASE("contact: a tetrahedron's sharp edges and corners get the sign right", "[contact]") {
  // A regular tetrahedron: face normals 109.5° apart, so a point beyond an
  // edge can lie behind one of the edge's faces; only the edge's own
  // pseudonormal gives its side.
  TriangleSurfaceParameters tetrahedron;
  tetrahedron.vertices = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  tetrahedron.triangles = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
  // The outward face planes (unit normal, offset), written independently.
  std::vector<std::pair<Vector3, double>> planes;
  for (const auto& tri : tetrahedron.triangles) {
    const Vector3& a = tetrahedron.vertices[tri[0]];
    Vector3 normal = (tetrahedron.vertices[tri[1]] - a).cross(tetrahedron.vertices[tri[2]] - a).normalized();
    if (normal.dot(a) < 0.0) normal = -normal;
    planes.emplace_back(normal, normal.dot(a));
  }
  const TriangleSurface body(tetrahedron);
  std::mt19937 random(5);
  std::uniform_real_distribution<double> coordinate(-2.0, 2.0);
  int outside_behind_a_face = 0;
  for (int k = 0; k < 4000; ++k) {
    const Vector3 p(coordinate(random), coordinate(random), coordinate(random));
    double largest = -1e300;
    int negative_planes = 0;
    for (const auto& [normal, offset] : planes) {
      largest = std::max(largest, normal.dot(p) - offset);
      negative_planes += normal.dot(p) - offset < 0.0;
    }
    const double gap = body.proximity(p).gap;
    INFO("point " << p.transpose());
    if (largest < 0.0) {
      REQUIRE(gap == Approx(largest).margin(1e-12));  // inside a convex body: the nearest face plane
    } else {
      REQUIRE(gap > 0.0);
      REQUIRE(gap >= largest - 1e-12);
      outside_behind_a_face += negative_planes > 0 && gap > largest + 1e-9;
    }
  }
  CHECK(outside_behind_a_face > 100);  // points off edges and corners were tried
}

TEST_CASE("contact: a triangulated sphere's signed distance within its chord error", "[contact]") {
  const double radius = 0.5;
  const TriangleSurfaceParameters mesh = icosphere(radius, 3);
  REQUIRE(mesh.triangles.size() == 1280);
  // Chord error: how far inside the sphere the farthest face plane lies.
  double chord_error = 0.0;
  for (const auto& tri : mesh.triangles) {
    const Vector3 normal =
        (mesh.vertices[tri[1]] - mesh.vertices[tri[0]]).cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]]).normalized();
    chord_error = std::max(chord_error, radius - normal.dot(mesh.vertices[tri[0]]));
  }
  REQUIRE(chord_error > 0.0);
  REQUIRE(chord_error < 0.01 * radius);
  RigidKinematics at;
  at.position = Vector3(0.1, -0.2, 0.3);
  const RigidBody<TriangleSurface, Fixed> body(TriangleSurface(mesh), Fixed{}, at);
  std::mt19937 random(11);
  std::normal_distribution<double> direction(0.0, 1.0);
  std::uniform_real_distribution<double> distance(0.2 * radius, 2.0 * radius);
  double largest_error = 0.0;
  for (int k = 0; k < 500; ++k) {
    const Vector3 offset =
        distance(random) * Vector3(direction(random), direction(random), direction(random)).normalized();
    const SurfaceProximity q = body.proximity(at.position + offset);
    const double exact = offset.norm() - radius;
    largest_error = std::max(largest_error, std::abs(q.gap - exact));
    REQUIRE(std::abs(q.gap - exact) <= chord_error * (1.0 + 1e-9));
    REQUIRE(q.normal.dot(offset.normalized()) > 0.9);
  }
  // The bound is not loose: the mesh is visibly off the sphere somewhere.
  CHECK(largest_error > 0.2 * chord_error);
}

TEST_CASE("contact: bad rigid bodies and penalty options are refused by name", "[contact]") {
  using Catch::Contains;
  CHECK_THROWS_WITH(Sphere(0.0), Contains("sphere radius = 0"));
  CHECK_THROWS_WITH(Sphere(-1.0), Contains("sphere radius = -1"));
  CHECK_THROWS_WITH(Cylinder({Vector3::UnitZ(), -0.1, 1.0, CylinderEnds::flat}), Contains("cylinder radius = -0.1"));
  CHECK_THROWS_WITH(Cylinder({Vector3::UnitZ(), 0.1, 0.0, CylinderEnds::flat}), Contains("cylinder length = 0"));
  CHECK_THROWS_WITH(Free({0.0, Vector3::Ones(), Vector3::Zero()}), Contains("rigid body mass = 0"));
  CHECK_THROWS_WITH(Free({-2.0, Vector3::Ones(), Vector3::Zero()}), Contains("rigid body mass = -2"));
  CHECK_THROWS_WITH((RigidBody<Sphere, Free>(Sphere(1.0), Free({1.0, Vector3(1, 0, 1), Vector3::Zero()}))),
                    Contains("rigid body principal inertia 1 = 0"));
  CHECK_THROWS_WITH(PenaltyContact({0.1, -0.2, 1.0}), Contains("friction_coefficient = -0.2"));
  CHECK_THROWS_WITH(PenaltyContact({0.0, 0.1, 1.0}), Contains("penalty stiffness_scale = 0"));
  CHECK_THROWS_WITH(PenaltyContact({-0.1, 0.1, 1.0}), Contains("penalty stiffness_scale = -0.1"));
  CHECK_THROWS_WITH(PenaltyContact({4.0, 0.1, 1.0}), Contains("penalty stiffness_scale = 4"));
  CHECK_NOTHROW(PenaltyContact({3.99, 0.1, 1.0}));
  CHECK_THROWS_WITH(PenaltyContact({0.1, 0.1, 1.5}), Contains("tangential_stiffness_ratio = 1.5"));

  TriangleSurfaceParameters open = cube_surface(1.0);
  open.triangles.pop_back();
  CHECK_THROWS_WITH(TriangleSurface(open), Contains("unmatched") && Contains("closed"));
  TriangleSurfaceParameters inside_out = cube_surface(1.0);
  for (auto& tri : inside_out.triangles) std::swap(tri[1], tri[2]);
  CHECK_THROWS_WITH(TriangleSurface(inside_out), Contains("triangle surface volume = -8"));
  TriangleSurfaceParameters degenerate = cube_surface(1.0);
  degenerate.vertices[7] = degenerate.vertices[6];  // collapses the edge 6-7: two triangles lose their area
  CHECK_THROWS_WITH(TriangleSurface(degenerate), Contains("area = 0") && Contains("degenerate"));
  TriangleSurfaceParameters out_of_range = cube_surface(1.0);
  out_of_range.triangles[3][1] = 8;
  CHECK_THROWS_WITH(TriangleSurface(out_of_range), Contains("triangle 3 corner 1 = 8"));

  // A particle in contact without mass.
  const RigidBody<Plane, Fixed> wall = fixed_wall(Vector3::Zero(), Vector3::UnitZ());
  const TestParticles massless = one_particle(Vector3(0, 0, 0.0005), Vector3::UnitZ(), Vector3::Zero(), 0.0, 0.002);
  PenaltyContact contact;
  ParticleContactLoads loads;
  CHECK_THROWS_WITH(contact.compute(massless.view(), wall, 1e-6, loads), Contains("mass of particle 0 = 0"));
}

TEST_CASE("contact: the particle touches with its face, half the thickness off the mid-surface", "[contact]") {
  const double h = 2e-3, m = 1e-3, dt = 1e-6, s = default_penalty_stiffness_scale;
  const double k = s * m / (dt * dt);  // the stated rule, written out
  RigidKinematics wall_at;
  wall_at.position = Vector3(0.3, -0.1, 0.05);
  const RigidBody<Plane, Fixed> wall(Plane(Vector3::UnitZ()), Fixed{}, wall_at);
  PenaltyContact contact;
  ParticleContactLoads loads;
  const double epsilon = 1e-6 * h, delta = 1e-3 * h;
  for (const double director_sign : {1.0, -1.0}) {
    const Vector3 d = director_sign * Vector3::UnitZ();
    const TestParticles clear = one_particle(Vector3(0, 0, 0.05 + h / 2 + epsilon), d, Vector3::Zero(), m, h);
    ContactStepResult result = contact.compute(clear.view(), wall, dt, loads);
    CHECK(result.contacts == 0);
    CHECK(loads.force[0].norm() == 0.0);
    const TestParticles touching = one_particle(Vector3(0, 0, 0.05 + h / 2 - delta), d, Vector3::Zero(), m, h);
    result = contact.compute(touching.view(), wall, dt, loads);
    CHECK(result.contacts == 1);
    CHECK((loads.force[0] - k * delta * Vector3::UnitZ()).norm() < 1e-9 * k * delta);
    CHECK(loads.moment[0].norm() < 1e-12 * k * delta * h);  // the arm is along the force
    CHECK((result.body_force + loads.force[0]).norm() == 0.0);
    CHECK(result.spring_energy == Approx(0.5 * k * delta * delta).epsilon(1e-9));
  }
}

TEST_CASE("contact: the moment of the offset is r × f on the particle, and its reaction about the body's centre",
          "[contact]") {
  const double h = 4e-3, m = 2e-3, dt = 1e-6, mu = 0.4;
  const double tilt = pi / 6;
  const Vector3 d(std::sin(tilt), 0.0, std::cos(tilt));
  const Vector3 x(0.01, 0.02, h / 2 * std::cos(tilt) - 1e-5);  // the lower face 10 µm into the wall
  RigidKinematics wall_at;
  wall_at.position = Vector3(-0.2, 0.1, 0.0);
  const RigidBody<Plane, Fixed> wall(Plane(Vector3::UnitZ()), Fixed{}, wall_at);
  const Vector3 r = -(h / 2) * d;  // to the lower face
  const double k = default_penalty_stiffness_scale * m / (dt * dt);
  const double penetration = -(x + r).z();
  ParticleContactLoads loads;
  {
    // Sliding slowly along +y: the tangential spring sticks, f_t = −k_t v Δt.
    PenaltyContact sticking({default_penalty_stiffness_scale, mu, 1.0});
    const double slow = 0.5;
    REQUIRE(k * slow * dt < mu * k * penetration);
    sticking.compute(one_particle(x, d, Vector3(0, slow, 0), m, h).view(), wall, dt, loads);
    CHECK(loads.force[0].y() == Approx(-k * slow * dt).epsilon(1e-12));
    CHECK((loads.moment[0] - r.cross(loads.force[0])).norm() < 1e-12 * loads.moment[0].norm());
  }
  PenaltyContact contact({default_penalty_stiffness_scale, mu, 1.0});
  // Sliding fast along +y: k_t v Δt exceeds μ f_n, the particle slips in one step.
  const double fast = 5.0;
  REQUIRE(k * fast * dt > mu * k * penetration);
  const TestParticles p = one_particle(x, d, Vector3(0, fast, 0), m, h);
  const ContactStepResult result = contact.compute(p.view(), wall, dt, loads);
  REQUIRE(result.contacts == 1);
  CHECK(loads.force[0].z() == Approx(k * penetration).epsilon(1e-12));
  CHECK(loads.force[0].y() == Approx(-mu * k * penetration).epsilon(1e-12));  // friction against the sliding
  const Vector3 expected_moment = r.cross(loads.force[0]);
  CHECK(expected_moment.norm() > 0.1 * h / 2 * loads.force[0].norm());
  CHECK((loads.moment[0] - expected_moment).norm() < 1e-12 * expected_moment.norm());
  const Vector3 body_moment = (x + r - wall_at.position).cross(-loads.force[0]);
  CHECK((result.body_moment - body_moment).norm() < 1e-12 * body_moment.norm());
}

TEST_CASE("contact: a point mass bounces off a penalty wall: impulse, energy and contact time", "[contact]") {
  const double h = 2e-3, m = 1e-3, dt = 1e-6, s = default_penalty_stiffness_scale, v0 = 2.0;
  const double omega = std::sqrt(s * m / (dt * dt) / m);
  const RigidBody<Plane, Fixed> wall = fixed_wall(Vector3::Zero(), Vector3::UnitZ());
  PenaltyContact contact;
  ParticleContactLoads loads;
  TestParticles p = one_particle(Vector3(0, 0, h / 2 + 50 * v0 * dt + 0.3 * v0 * dt), Vector3::UnitZ(),
                                 Vector3(0, 0, -v0), m, h);
  double impulse = 0.0, work = 0.0, lowest = p.position[0].z();
  double touch_time = -1.0, leave_time = -1.0;
  double previous_gap = p.position[0].z() - h / 2;
  for (long n = 0; n < 400; ++n) {
    const double time = n * dt;
    const ContactStepResult result = contact.compute(p.view(), wall, dt, loads);
    work += result.work;
    const double span = n == 0 ? 0.5 * dt : dt;
    impulse += span * loads.force[0].z();
    p.velocity[0] += span * loads.force[0] / m;
    p.position[0] += dt * p.velocity[0];
    lowest = std::min(lowest, p.position[0].z());
    const double gap = p.position[0].z() - h / 2;
    // The face crosses the wall between steps: interpolate the crossing.
    if (previous_gap > 0.0 && gap <= 0.0 && touch_time < 0.0)
      touch_time = time + dt * previous_gap / (previous_gap - gap);
    if (previous_gap < 0.0 && gap >= 0.0 && leave_time < 0.0)
      leave_time = time + dt * previous_gap / (previous_gap - gap);
    previous_gap = gap;
  }
  REQUIRE(touch_time > 0.0);
  REQUIRE(leave_time > touch_time);
  const double v_after = p.velocity[0].z();
  // ∫F dt is the momentum change.
  CHECK(impulse == Approx(m * (v_after + v0)).epsilon(0.005));
  CHECK(impulse == Approx(2 * m * v0).epsilon(0.005));
  // The kinetic energy is kept.
  CHECK(v_after * v_after == Approx(v0 * v0).epsilon(0.01));
  CHECK(std::abs(work) < 0.01 * 0.5 * m * v0 * v0);
  // Half a period of the penalty spring, ω = √(k/m) = √s / Δt.
  CHECK(leave_time - touch_time == Approx(pi / omega).epsilon(0.02));
  // The deepest penetration of the face, v0/ω: the mid-surface stays h/2 − v0/ω from the wall.
  CHECK(h / 2 - lowest == Approx(v0 / omega).epsilon(0.02));
}

TEST_CASE("contact: a free sphere hits a free particle head on: momentum kept, the elastic collision's velocities",
          "[contact]") {
  const double h = 2e-3, m = 1e-3, dt = 1e-6, radius = 0.02, body_mass = 2e-3, v1 = 3.0;
  RigidKinematics start;
  start.position = Vector3(-radius - h / 2 - 20 * v1 * dt, 0, 0);
  start.velocity = Vector3(v1, 0, 0);
  const double inertia = 0.4 * body_mass * radius * radius;
  RigidBody<Sphere, Free> ball(Sphere(radius), Free({body_mass, Vector3::Constant(inertia), Vector3::Zero()}), start);
  TestParticles p = one_particle(Vector3::Zero(), Vector3::UnitX(), Vector3::Zero(), m, h);
  PenaltyContact contact;
  ParticleContactLoads loads;
  const Vector3 momentum0 = body_mass * start.velocity;
  for (long n = 0; n < 200; ++n) {
    const StepTime at{n, n * dt};
    ball.clear_contact_load();
    const ContactStepResult result = contact.compute(p.view(), ball, dt, loads);
    ball.add_contact_load(result.body_force, result.body_moment);
    const double span = n == 0 ? 0.5 * dt : dt;
    p.velocity[0] += span * loads.force[0] / m;
    p.position[0] += dt * p.velocity[0];
    ball.advance(at, dt);
    const Vector3 momentum = body_mass * ball.velocity() + m * p.velocity[0];
    REQUIRE((momentum - momentum0).norm() < 1e-12 * momentum0.norm());
  }
  // Elastic head-on collision: v1' = (M − m)/(M + m) v1, v2' = 2M/(M + m) v1.
  CHECK(ball.velocity().x() == Approx((body_mass - m) / (body_mass + m) * v1).epsilon(0.01));
  CHECK(p.velocity[0].x() == Approx(2 * body_mass / (body_mass + m) * v1).epsilon(0.01));
  CHECK(ball.angular_velocity().norm() < 1e-9);
  CHECK(ball.contact_impulse().x() == Approx(body_mass * (ball.velocity().x() - v1)).epsilon(1e-9));
}

TEST_CASE("contact: a block sliding on a wall decelerates at mu g", "[contact]") {
  const double h = 2e-3, m = 1e-3, dt = 1e-5, mu = 0.3, g = 9.81, v0 = 0.1;
  const double k = default_penalty_stiffness_scale * m / (dt * dt);
  const RigidBody<Plane, Fixed> wall = fixed_wall(Vector3::Zero(), Vector3::UnitZ());
  PenaltyContact contact({default_penalty_stiffness_scale, mu, 1.0});
  ParticleContactLoads loads;
  // Resting on its contact spring: the face m g / k into the wall.
  TestParticles p = one_particle(Vector3(0, 0, h / 2 - m * g / k), Vector3::UnitZ(), Vector3(v0, 0, 0), m, h);
  const Vector3 gravity(0, 0, -g);
  const double half_speed_time = 0.5 * v0 / (mu * g);
  const long steps = static_cast<long>(half_speed_time / dt);
  double dissipation = 0.0, work = 0.0;
  for (long n = 0; n < steps; ++n) {
    const ContactStepResult result = contact.compute(p.view(), wall, dt, loads);
    dissipation += result.friction_dissipation;
    work += result.work;
    CHECK((result.body_force + loads.force[0]).norm() == 0.0);
    const double span = n == 0 ? 0.5 * dt : dt;
    p.velocity[0] += span * (loads.force[0] / m + gravity);
    p.position[0] += dt * p.velocity[0];
  }
  // v^{N−½} at t = (N − ½) Δt.
  const double time = (steps - 0.5) * dt;
  const double expected = v0 - mu * g * time;
  CHECK(p.velocity[0].x() == Approx(expected).epsilon(0.01));
  CHECK((v0 - p.velocity[0].x()) / time == Approx(mu * g).epsilon(0.01));
  CHECK(std::abs(p.velocity[0].z()) < 1e-6 * v0);
  // The kinetic energy lost is what friction dissipated, and the contact work is minus it.
  const double lost = 0.5 * m * (v0 * v0 - p.velocity[0].squaredNorm());
  CHECK(dissipation == Approx(lost).epsilon(0.01));
  CHECK(-work == Approx(lost).epsilon(0.01));
}

TEST_CASE("contact: rigid motions: prescribed, free under gravity, free spin", "[contact]") {
  const double dt = 1e-4, a = 3.0;
  const long steps = 1000;
  auto ramp = [a](double t) { return Vector3(0, 0, a * t); };
  RigidBody<Sphere, Prescribed<decltype(ramp)>> driven(Sphere(0.1), prescribed(ramp));
  const Vector3 g(0, -9.81, 0);
  RigidKinematics thrown;
  thrown.velocity = Vector3(1.0, 2.0, 0.0);
  RigidBody<Plane, Free> falling(Plane(Vector3::UnitY()), Free({5.0, Vector3::Zero(), g}), thrown);
  const double inertia = 0.02, torque = 0.3;
  RigidBody<Sphere, Free> spun(Sphere(0.1), Free({1.0, Vector3::Constant(inertia), Vector3::Zero()}));
  for (long n = 0; n < steps; ++n) {
    const StepTime at{n, n * dt};
    driven.advance(at, dt);
    falling.advance(at, dt);
    spun.clear_contact_load();
    spun.add_contact_load(Vector3::Zero(), Vector3(0, 0, torque));
    spun.advance(at, dt);
  }
  const double t = steps * dt;
  CHECK(driven.position().z() == Approx(0.5 * a * t * t).epsilon(1e-12));
  const Vector3 expected_fall = thrown.velocity * t + 0.5 * g * t * t;
  CHECK((falling.position() - expected_fall).norm() < 1e-12 * expected_fall.norm());
  // ω at t − Δt/2, and the turned angle ½ (M/I) t² (the central difference is exact for a constant moment).
  CHECK(spun.angular_velocity().z() == Approx(torque / inertia * (t - 0.5 * dt)).epsilon(1e-12));
  const double angle = Eigen::AngleAxisd(spun.orientation()).angle();
  CHECK(angle == Approx(0.5 * torque / inertia * t * t).epsilon(1e-9));
}

TEST_CASE("contact: a prescribed spin turns the body and a free tumbling body keeps its angular momentum", "[contact]") {
  const double dt = 1e-3, spin = 0.5;
  const long steps = 1000;
  auto still = [](double) { return Vector3::Zero(); };
  auto turning = [spin](double) { return Vector3(0, 0, spin); };
  RigidBody<Cylinder, Prescribed<decltype(still), decltype(turning)>> turned(
      Cylinder({Vector3::UnitX(), 0.1, 1.0, CylinderEnds::flat}), prescribed(still, turning));
  // A torque-free asymmetric body spinning near its axis of largest inertia.
  const Vector3 inertia(1.0, 2.0, 3.0);
  RigidKinematics start;
  start.angular_velocity = Vector3(0.3, 0.2, 3.0);
  RigidBody<Sphere, Free> tumbling(Sphere(0.1), Free({1.0, inertia, Vector3::Zero()}), start);
  const auto angular_momentum = [&inertia](const RigidKinematics& k) {
    const Matrix3 to_world = k.orientation.toRotationMatrix();
    return Vector3(to_world * inertia.cwiseProduct(to_world.transpose() * k.angular_velocity));
  };
  const Vector3 momentum0 = angular_momentum(tumbling.kinematics());
  double largest_drift = 0.0;
  for (long n = 0; n < 5 * steps; ++n) {
    const StepTime at{n, n * dt};
    if (n < steps) turned.advance(at, dt);
    tumbling.advance(at, dt);
    largest_drift = std::max(largest_drift, (angular_momentum(tumbling.kinematics()) - momentum0).norm());
  }
  // The cylinder's axis (body x) turned by spin · t about z.
  const Vector3 axis = turned.orientation() * Vector3::UnitX();
  const double angle = spin * steps * dt;
  CHECK((axis - Vector3(std::cos(angle), std::sin(angle), 0.0)).norm() < 1e-12);
  CHECK(turned.proximity(Vector3(0.0, 0.0, 0.3)).gap == Approx(0.2).epsilon(1e-12));
  // Over 5 s (2.4 turns) the world angular momentum stays within 1 %.
  CHECK(largest_drift < 0.01 * momentum0.norm());
}

TEST_CASE("contact: a block pushed sideways below mu m g sticks without creeping", "[contact]") {
  const double h = 2e-3, m = 1e-3, dt = 1e-5, mu = 0.3, g = 9.81;
  const double k = default_penalty_stiffness_scale * m / (dt * dt);
  const RigidBody<Plane, Fixed> wall = fixed_wall(Vector3::Zero(), Vector3::UnitZ());
  PenaltyContact contact({default_penalty_stiffness_scale, mu, 1.0});
  ParticleContactLoads loads;
  TestParticles p = one_particle(Vector3(0, 0, h / 2 - m * g / k), Vector3::UnitZ(), Vector3::Zero(), m, h);
  const Vector3 push(0.5 * mu * m * g, 0, 0);
  const Vector3 gravity(0, 0, -g);
  double farthest = 0.0, dissipation = 0.0;
  for (long n = 0; n < 20000; ++n) {  // 0.2 s: a creep of 1 % of μ g would move it 6 µm
    const ContactStepResult result = contact.compute(p.view(), wall, dt, loads);
    dissipation += result.friction_dissipation;
    const double span = n == 0 ? 0.5 * dt : dt;
    p.velocity[0] += span * (loads.force[0] / m + gravity + push / m);
    p.position[0] += dt * p.velocity[0];
    farthest = std::max(farthest, std::abs(p.position[0].x()));
  }
  // The tangential spring (k_t = k) holds it: undamped, a suddenly applied push
  // stretches it to at most twice the static F / k_t (5 % allowed for the discrete oscillator).
  CHECK(farthest <= 2.05 * push.x() / k);
  CHECK(farthest >= 1.9 * push.x() / k);
  CHECK(dissipation == 0.0);
}

TEST_CASE("contact: particles in chunks give the bits of one pass", "[contact]") {
  const double h = 2e-3, dt = 1e-6, radius = 0.05;
  RigidKinematics at;
  at.velocity = Vector3(0.0, 0.0, -1.0);
  const RigidBody<Sphere, Free> ball(Sphere(radius), Free({0.5, Vector3::Constant(5e-4), Vector3::Zero()}), at);
  // A 9 × 9 sheet just under the sphere, the middle pressed in, sliding sideways.
  TestParticles sheet;
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) {
      const Vector3 x(0.004 * (i - 4), 0.004 * (j - 4), -radius - h / 2 + 1e-3);
      sheet.position.push_back(x);
      sheet.director.push_back(Vector3(0.05 * (i - 4), 0.0, 1.0).normalized());
      sheet.velocity.push_back(Vector3(0.3, -0.1 * j, 0.0));
      sheet.angular_velocity.push_back(Vector3(0.0, 2.0 * i, 0.0));
      sheet.mass.push_back(1e-4 * (1.0 + 0.1 * j));
      sheet.thickness.push_back(h);
    }
  PenaltyContact whole({0.2, 0.3, 0.8});
  PenaltyContact chunked({0.2, 0.3, 0.8});
  ParticleContactLoads whole_loads, chunk_loads;
  for (int step = 0; step < 3; ++step) {
    const ContactStepResult one = whole.compute(sheet.view(), ball, dt, whole_loads);
    chunked.prepare(sheet.view(), dt, chunk_loads);
    ContactStepResult sum;
    for (std::size_t first = 0; first < sheet.position.size(); first += 16)
      PenaltyContact::accumulate(
          sum, chunked.compute_range(sheet.view(), ball, dt, chunk_loads, first,
                                     std::min(first + 16, sheet.position.size())));
    REQUIRE(one.contacts > 5);
    CHECK(sum.contacts == one.contacts);
    for (std::size_t i = 0; i < sheet.position.size(); ++i) {
      REQUIRE(chunk_loads.force[i] == whole_loads.force[i]);
      REQUIRE(chunk_loads.moment[i] == whole_loads.moment[i]);
    }
    // The body's reaction balances the particles' forces.
    Vector3 total = Vector3::Zero();
    for (const Vector3& f : whole_loads.force) total += f;
    CHECK((one.body_force + total).norm() < 1e-12 * total.norm());
    CHECK((sum.body_force - one.body_force).norm() < 1e-12 * one.body_force.norm());
    for (std::size_t i = 0; i < sheet.position.size(); ++i) sheet.position[i] += dt * sheet.velocity[i];
  }
}

namespace {

// Enclosed volume of a triangulation, Σ a · (b × c) / 6 (divergence theorem),
// computed here rather than taken from TriangleSurface::volume().
double enclosed_volume(const SurfaceMesh& mesh) {
  double volume = 0.0;
  for (const auto& t : mesh.triangles)
    volume += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]])) / 6.0;
  return volume;
}

// Every vertex of a placed mesh lies on the body's surface.
template <class Shape, class Motion>
double largest_vertex_gap(const RigidBody<Shape, Motion>& body, const SurfaceMesh& mesh) {
  double largest = 0.0;
  for (const Vector3& vertex : mesh.vertices) largest = std::max(largest, std::abs(body.proximity(vertex).gap));
  return largest;
}

RigidKinematics turned_and_moved() {
  RigidKinematics at;
  at.position = Vector3(0.3, -0.1, 0.7);
  at.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vector3(1.0, 2.0, -0.5).normalized()));
  return at;
}

}  // namespace

TEST_CASE("contact: drawn surfaces are closed, outward, on the shape and converge to its volume", "[contact]") {
  const double radius = 0.02, length = 0.05;
  SECTION("sphere") {
    const RigidBody<Sphere, Fixed> body(Sphere(radius), Fixed{}, turned_and_moved());
    const SurfaceMesh coarse = place_surface_mesh(body, {});
    // TriangleSurface refuses an open, inconsistently turned or inward surface.
    const TriangleSurface closed(TriangleSurfaceParameters{coarse.vertices, coarse.triangles});
    CHECK(largest_vertex_gap(body, coarse) < 1e-12 * radius);
    const double exact = 4.0 / 3.0 * pi * radius * radius * radius;
    const SurfaceMesh local = surface_mesh(Sphere(radius), {32});
    const SurfaceMesh fine = surface_mesh(Sphere(radius), {64});
    const double coarse_error = exact - enclosed_volume(local);
    const double fine_error = exact - enclosed_volume(fine);
    // Inscribed: below the sphere's volume, by a chord error of second order.
    CHECK(closed.volume() == Approx(enclosed_volume(local)).epsilon(1e-12));
    CHECK(coarse_error > 0.0);
    CHECK(coarse_error < 0.02 * exact);
    CHECK(coarse_error / fine_error == Approx(4.0).epsilon(0.05));
  }
  SECTION("flat-ended cylinder: a prism of exactly n/2 R² sin(2π/n) L") {
    const Cylinder shape({Vector3(0.0, 1.0, 1.0), radius, length, CylinderEnds::flat});
    const RigidBody<Cylinder, Fixed> body(shape, Fixed{}, turned_and_moved());
    const SurfaceMesh placed = place_surface_mesh(body, {}, {24});
    const TriangleSurface closed(TriangleSurfaceParameters{placed.vertices, placed.triangles});
    CHECK(largest_vertex_gap(body, placed) < 1e-12 * radius);
    CHECK(closed.volume() == Approx(12.0 * radius * radius * std::sin(2.0 * pi / 24.0) * length).epsilon(1e-12));
  }
  SECTION("capsule") {
    const Cylinder shape({Vector3(1.0, 0.0, 0.0), radius, length, CylinderEnds::hemispherical});
    const RigidBody<Cylinder, Fixed> body(shape, Fixed{}, turned_and_moved());
    const SurfaceMesh placed = place_surface_mesh(body, {}, {48});
    const TriangleSurface closed(TriangleSurfaceParameters{placed.vertices, placed.triangles});
    CHECK(largest_vertex_gap(body, placed) < 1e-12 * radius);
    const double exact = pi * radius * radius * (length + 4.0 / 3.0 * radius);
    CHECK(closed.volume() < exact);
    CHECK(closed.volume() > 0.99 * exact);
  }
  SECTION("triangle surface: its own triangles, placed") {
    const RigidBody<TriangleSurface, Fixed> body(TriangleSurface(cube_surface(0.1)), Fixed{}, turned_and_moved());
    const SurfaceMesh placed = place_surface_mesh(body, {});
    CHECK(placed.triangles == body.shape().triangles());
    CHECK(largest_vertex_gap(body, placed) < 1e-12);
  }
  SECTION("plane: a patch in the wall, facing out, reaching past the model") {
    RigidKinematics at;
    at.position = Vector3(0.0, 0.0, -0.01);
    const RigidBody<Plane, Fixed> wall(Plane(Vector3(0.0, 0.0, 1.0)), Fixed{}, at);
    const ModelExtent model{Vector3(0.0, 0.0, 0.0), Vector3(0.4, 0.2, 0.0)};
    const SurfaceMesh patch = place_surface_mesh(wall, model);
    REQUIRE(patch.triangles.size() == 2);
    CHECK(largest_vertex_gap(wall, patch) < 1e-15);
    for (const auto& t : patch.triangles) {
      const Vector3 normal = (patch.vertices[t[1]] - patch.vertices[t[0]]).cross(patch.vertices[t[2]] - patch.vertices[t[0]]);
      CHECK(normal.normalized().dot(Vector3::UnitZ()) == Approx(1.0));
    }
    // Centred under the model, each corner beyond the model's corners.
    Vector3 lower = patch.vertices[0], upper = patch.vertices[0];
    for (const Vector3& v : patch.vertices) {
      lower = lower.cwiseMin(v);
      upper = upper.cwiseMax(v);
    }
    CHECK((0.5 * (lower + upper) - Vector3(0.2, 0.1, -0.01)).norm() < 1e-15);
    CHECK(lower.x() < 0.0);
    CHECK(lower.y() < 0.0);
    CHECK(upper.x() > 0.4);
    CHECK(upper.y() > 0.2);
  }
  SECTION("too few segments are refused by name") {
    CHECK_THROWS_WITH(surface_mesh(Sphere(radius), {2}), Catch::Contains("surface mesh segments"));
  }
}
