// Fuzz test of the public API with bad input: a fixed seed draws cases
// from the families of bad input the library must refuse (bad geometry, options,
// sets, loads, conditions, run control, pre-cracks), each with a random victim
// (particle, quad, option) and a random bad value (NaN, ±infinity, negative,
// zero, huge, a duplicate, an index out of range). Every case must end in a
// sphshell::Error whose message names what it should; nothing else may leave
// the API. Bounded: small models, a fixed number of cases.
#include "bad_input_support.hpp"

#include <cmath>
#include <functional>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace bad_input;

namespace {

constexpr unsigned fuzz_seed = 20261201u;
constexpr int cases_per_family = 12;

struct Case {
  std::string expected;        // a piece the message must hold
  std::function<void()> run;   // must throw sphshell::Error
};

struct Family {
  const char* name;
  std::function<Case(std::mt19937&)> draw;
};

double bad_number(std::mt19937& rng, bool allow_negative = true) {
  const double choices[] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                            -std::numeric_limits<double>::infinity(), allow_negative ? -1.0 : 0.0,
                            allow_negative ? -1e-300 : 0.0};
  return choices[std::uniform_int_distribution<int>(0, 4)(rng)];
}
int pick(std::mt19937& rng, int count) { return std::uniform_int_distribution<int>(0, count - 1)(rng); }

ShellModel plate() { return ShellModel::rectangular_plate(0.1, 0.1, 6, 6, 0.005); }

std::vector<Family> families() {
  std::vector<Family> all;
  all.push_back({"non-finite particle coordinate (from_quads)", [](std::mt19937& rng) {
                   QuadPlate p;
                   const int victim = pick(rng, static_cast<int>(p.positions.size()));
                   p.positions[victim][pick(rng, 3)] = std::numeric_limits<double>::quiet_NaN();
                   return Case{"particle " + std::to_string(victim) + " position", [p] { p.build(); }};
                 }});
  all.push_back({"repeated quad corner", [](std::mt19937& rng) {
                   QuadPlate p;
                   const int q = pick(rng, static_cast<int>(p.quads.size()));
                   const int k = pick(rng, 3);
                   p.quads[q][k + 1] = p.quads[q][k];
                   return Case{"quad " + std::to_string(q) + " corners", [p] { p.build(); }};
                 }});
  all.push_back({"quad corner out of range", [](std::mt19937& rng) {
                   QuadPlate p;
                   const int q = pick(rng, static_cast<int>(p.quads.size()));
                   p.quads[q][pick(rng, 4)] = pick(rng, 2) ? -1 - pick(rng, 5) : 25 + pick(rng, 100);
                   return Case{"quad " + std::to_string(q) + " corner", [p] { p.build(); }};
                 }});
  all.push_back({"bow-tie or clockwise quad", [](std::mt19937& rng) {
                   QuadPlate p;
                   const int q = pick(rng, static_cast<int>(p.quads.size()));
                   const bool bow = pick(rng, 2) == 0;
                   if (bow)
                     std::swap(p.quads[q][2], p.quads[q][3]);
                   else
                     for (Quad& quad : p.quads) std::swap(quad[1], quad[3]);
                   return Case{bow ? "bow-tie" : "clockwise", [p] { p.build(); }};
                 }});
  all.push_back({"flipped normal", [](std::mt19937& rng) {
                   QuadPlate p;
                   const int victim = pick(rng, static_cast<int>(p.normals.size()));
                   p.normals[victim] = -p.normals[victim];
                   return Case{"particle " + std::to_string(victim) + " normal", [p] { p.build(); }};
                 }});
  all.push_back({"bad area (general constructor)", [](std::mt19937& rng) {
                   GeneralPlate p;
                   const bool stress = pick(rng, 2) == 0;
                   const int victim = pick(rng, static_cast<int>(stress ? p.stress_areas.size() : p.areas.size()));
                   const double value = pick(rng, 2) ? bad_number(rng) : 1e6;
                   (stress ? p.stress_areas : p.areas)[victim] = value;
                   const std::string who = (stress ? "stress point " : "particle ") + std::to_string(victim) + " area";
                   return Case{who, [p] { p.build(); }};
                 }});
  all.push_back({"bad thickness", [](std::mt19937& rng) {
                   const double value = pick(rng, 2) ? bad_number(rng) : 1e3 * (1 + pick(rng, 9));
                   return Case{"thickness", [value] { ShellModel::rectangular_plate(0.1, 0.1, 6, 6, value); }};
                 }});
  all.push_back({"bad solver option", [](std::mt19937& rng) {
                   SolverOptions options;
                   const double value = bad_number(rng);
                   const char* names[] = {"density", "safety_factor", "damping", "support_radius_factor",
                                          "energy_tolerance", "time_step", "shear_correction"};
                   const int which = pick(rng, 7);
                   double* fields[] = {&options.density,          &options.safety_factor,   &options.damping,
                                       &options.support_radius_factor, &options.energy_tolerance, &options.time_step,
                                       &options.shear_correction};
                   *fields[which] = value;
                   return Case{names[which], [options] { ElasticSolver(plate(), steel, options); }};
                 }});
  all.push_back({"negative progress interval or step budget", [](std::mt19937& rng) {
                   SolverOptions options;
                   const bool progress = pick(rng, 2) == 0;
                   if (progress)
                     options.progress_interval = -1 - pick(rng, 1000);
                   else
                     options.max_steps_per_run = -pick(rng, 1000);
                   return Case{progress ? "progress_interval" : "max_steps_per_run",
                               [options] { ElasticSolver(plate(), steel, options); }};
                 }});
  all.push_back({"particle set with a duplicate or out of range", [](std::mt19937& rng) {
                   const int victim = pick(rng, 36);
                   const ParticleSet set =
                       pick(rng, 2) == 0 ? ParticleSet{victim, victim} : ParticleSet{victim, 36 + pick(rng, 50)};
                   const int which = pick(rng, 4);
                   return Case{"particle index", [set, which] {
                                 ElasticSolver solver(plate(), steel);
                                 if (which == 0) solver.clamp(set);
                                 if (which == 1) solver.add_point_force(set, Vector3(0, 0, 1));
                                 if (which == 2) solver.add_gravity(set, Vector3(0, 0, -9.81));
                                 if (which == 3) solver.simply_support(set);
                               }};
                 }});
  all.push_back({"bad time function", [](std::mt19937& rng) {
                   const bool ramp = pick(rng, 2) == 0;
                   const double value = ramp ? bad_number(rng)
                                             : std::vector<double>{std::numeric_limits<double>::quiet_NaN(),
                                                                   std::numeric_limits<double>::infinity(),
                                                                   -std::numeric_limits<double>::infinity()}[pick(rng, 3)];
                   const bool pressure = pick(rng, 2) == 0;
                   return Case{ramp ? "time_function::Ramp" : "time_function::Step", [value, ramp, pressure] {
                                 ElasticSolver solver(plate(), steel);
                                 if (ramp && pressure) solver.add_uniform_pressure({7}, 1.0, time_function::Ramp{value});
                                 if (ramp && !pressure) solver.add_point_force({7}, Vector3(0, 0, 1), time_function::Ramp{value});
                                 if (!ramp && pressure) solver.add_uniform_pressure({7}, 1.0, time_function::Step{value});
                                 if (!ramp && !pressure) solver.add_point_moment({7}, Vector3(1, 0, 0), time_function::Step{value});
                               }};
                 }});
  all.push_back({"conflicting conditions", [](std::mt19937& rng) {
                   const bool clamp_first = pick(rng, 2) == 0;
                   return Case{"conflicts", [clamp_first] {
                                 ElasticSolver solver(plate(), steel);
                                 auto motion = [](const Vector3&, double) { return Vector3(0.1, 0, 0); };
                                 if (clamp_first) {
                                   solver.clamp(solver.model().set("x_min"));
                                   solver.prescribe_velocity(solver.model().set("y_min"), motion);
                                 } else {
                                   solver.prescribe_velocity(solver.model().set("y_min"), motion);
                                   solver.symmetry_plane(solver.model().set("x_min"), Vector3::UnitX());
                                 }
                               }};
                 }});
  all.push_back({"run_until into the past or beyond the budget", [](std::mt19937& rng) {
                   const bool past = pick(rng, 2) == 0;
                   const double t = past ? -std::pow(10.0, -pick(rng, 8)) : std::pow(10.0, 4 + pick(rng, 6));
                   return Case{past ? "before the current time" : "max_steps_per_run", [t] {
                                 ElasticSolver solver(plate(), steel);
                                 solver.run_until(t);
                               }};
                 }});
  all.push_back({"index out of range in a query", [](std::mt19937& rng) {
                   const int victim = pick(rng, 2) ? -1 - pick(rng, 10) : 36 + pick(rng, 1000);
                   const int which = pick(rng, 4);
                   return Case{"index", [victim, which] {
                                 const ShellModel model = plate();
                                 if (which == 0) model.particle_thickness(static_cast<std::size_t>(victim));
                                 ElasticSolver solver(model, steel);
                                 if (which == 1) solver.displacement(victim);
                                 if (which == 2) solver.equivalent_stress(victim, 0);
                                 if (which == 3) solver.is_fragment(victim);
                               }};
                 }});
  all.push_back({"redefined set", [](std::mt19937& rng) {
                   const char* names[] = {"boundary", "x_min", "x_max", "y_min", "y_max", "centre"};
                   const std::string name = names[pick(rng, 6)];
                   return Case{"particle set name = " + name, [name] {
                                 ShellModel model = plate();
                                 model.define_set(name, [](const Vector3&) { return true; });
                               }};
                 }});
  all.push_back({"pre-crack off the surface or repeated", [](std::mt19937& rng) {
                   const bool off = pick(rng, 2) == 0;
                   const double lift = (0.3 + 0.3 * std::uniform_real_distribution<double>(0, 1)(rng)) * 0.02;
                   return Case{off ? "surface" : "repeats", [off, lift] {
                                 CrackSolver solver(plate(), steel);
                                 const std::vector<Vector3> line{Vector3(0.05, -0.001, off ? lift : 0.0),
                                                                 Vector3(0.05, 0.05, off ? lift : 0.0)};
                                 solver.add_precrack(line);
                                 solver.add_precrack(line);
                               }};
                 }});
  return all;
}

}  // namespace

TEST_CASE("Fuzzed bad input always ends in a named sphshell::Error", "[bad_input][fuzz]") {
  std::mt19937 rng(fuzz_seed);
  int cases = 0, errors = 0;
  for (const Family& family : families())
    for (int k = 0; k < cases_per_family; ++k) {
      const Case c = family.draw(rng);
      ++cases;
      std::string message;
      bool named_error = false;
      try {
        c.run();
      } catch (const Error& error) {
        message = error.what();
        named_error = true;
      } catch (const std::exception& other) {
        message = std::string("other exception: ") + other.what();
      }
      INFO("family: " << family.name << ", case " << k << ", expected '" << c.expected << "', got: " << message);
      CHECK(named_error);
      CHECK(message.find(c.expected) != std::string::npos);
      if (named_error && message.find(c.expected) != std::string::npos) ++errors;
    }
  std::cout << "bad-input fuzz: " << errors << " of " << cases << " cases ended in a named sphshell::Error (seed "
            << fuzz_seed << ")\n";
  CHECK(errors == cases);
}
