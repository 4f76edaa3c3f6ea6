// The paper's clamped square plate under a uniform step pressure (§3, Table 3,
// Fig. 5): linear, nonlinear, elastoplastic and damage analyses (Figs 8-19) and,
// with --case fracture, the edge cracks of §3.2.4 (Figs 20-22).
// `square_plate --help` lists the options, their defaults and the files written.

#include <sphshell/approx/all.hpp>
#include <sphshell/crack/all.hpp>
#include <sphshell/io/csv_probe.hpp>
#include <sphshell/io/svg_plot.hpp>
#include <sphshell/kernel/all.hpp>
#include <sphshell/material/all.hpp>
#include <sphshell/solver.hpp>
#include <sphshell/thickness/all.hpp>

#include "example_arguments.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

using namespace sphshell;

namespace {

struct Arguments {
  std::string analysis = "plastic";
  std::string rule = "gauss5";
  int n = 51;
  double pressure = 0.0;  // 0: the case's default (1 MPa, 5 MPa for fracture)
  double end_time = 4e-3;
  double particle_share = SolverOptions{}.particle_integration_share;
  std::string output = "square_plate";
  bool frames = false;
};

// Nothing when --help was asked for.
std::optional<Arguments> parse(int argc, char** argv) {
  Arguments a;
  example::CommandLine command_line(
      "square_plate",
      "The paper's square plate (§3, Table 3, Fig. 5): L = 0.5 m, d = 0.01 m, steel (ρ 7850 kg/m³, "
      "E 210 GPa, ν 0.3, σs0 235 MPa, Ep = 0), all edges clamped, uniform step pressure q, first-order "
      "MLS with the cubic spline. Test point A is the plate centre, B the stress point at the middle of "
      "an edge, half a spacing from the clamped boundary. --case fracture is §3.2.4: q = 5 MPa unless "
      "--pressure is given, Lemaitre damage (ε̄sp 0.02, ε̄cp 0.37, Dc 0.24) with crack::LineSegments; "
      "Fig. 21 follows one of the four edge cracks, so the longest is reported beside the total. "
      "--case linear also prints closed forms: the step load drives the centre to about twice the "
      "static Mindlin deflection, with the period of the fundamental mode.");
  command_line.choice("--case", a.analysis, {"linear", "nonlinear", "plastic", "damage", "fracture"},
                      "analysis: linear or geometrically nonlinear elastic, J2 plasticity, Lemaitre damage, "
                      "or damage with cracks");
  command_line.choice("--rule", a.rule, {"gauss5", "gauss3", "gauss7", "global"},
                      "through-thickness integration: 5, 3 or 7 Gauss points, or resultants (thickness::Global)");
  command_line.integer("--n", a.n, "particles along each edge, at least 3 (n × n particles, (n - 1)² stress points)");
  command_line.custom("--pressure", "X", "Pa", "1e6, 5e6 with --case fracture", "step pressure q, > 0",
                      [&a](const std::string& text) { a.pressure = example::parse_number("--pressure", text); });
  command_line.number("--end-time", a.end_time, "s", "simulated time");
  command_line.custom("--particle-share", "X", "-",
                      example::format_number(a.particle_share) + ", the library's",
                      "SolverOptions::particle_integration_share, in [0, 1): the share of the membrane and "
                      "bending work the particles integrate",
                      [&a](const std::string& text) {
                        a.particle_share = example::parse_particle_share("--particle-share", text);
                      });
  command_line.output_folder(a.output);
  command_line.flag("--frames", a.frames,
                    "also write ParaView frames every 0.1 ms of simulated time (particles.pvd, "
                    "stress_points.pvd; cracks.pvd with --case fracture)");
  command_line.writes("history.csv",
                      "every 5th step: t, centre deflection w_A, equivalent stress and plastic strain at A "
                      "and B per integral point, damage at B; with --case fracture also the total and the "
                      "longest crack length, crack count, damaged stress points and fragments");
  command_line.writes("history.svg", "chart of w_A (paper Figs 8, 22) and, with --case fracture, the crack "
                                     "lengths (Fig. 21)");
  command_line.writes("*.pvd, *.vtu", "with --frames: ParaView frames of particles, stress points and cracks");
  if (!command_line.parse(argc, argv)) return std::nullopt;
  if (a.n < 3) detail::invalid_parameter("--n", a.n, "must be at least 3");
  detail::require_positive("--end-time", a.end_time);
  if (a.pressure != 0.0) detail::require_positive("--pressure", a.pressure);
  return a;
}

constexpr double length = 0.5, thickness = 0.01, density = 7850.0, E = 210e9, nu = 0.3;
constexpr double sigma_y0 = 235e6, Ep = 0.0, eps_s = 0.02, eps_c = 0.37, Dc = 0.24;
constexpr double bending_stiffness = E * thickness * thickness * thickness / (12 * (1 - nu * nu));

// Static centre deflection of the clamped square Mindlin plate at L/d = 50.
double static_mindlin_deflection(double pressure) {
  return 0.0012754 * pressure * std::pow(length, 4) / bending_stiffness;
}

template <class Rule, class Material, class Crack = crack::None>
int run(const Arguments& a, const typename Material::Parameters& parameters) {
  const double pressure = a.pressure > 0.0 ? a.pressure : (Crack::enabled ? 5e6 : 1e6);
  SolverOptions options;
  options.density = density;
  options.nonlinear = a.analysis != "linear";
  options.output_directory = a.frames ? a.output : "";
  options.output_interval = a.frames ? 1e-4 : 0.0;
  options.progress_interval = 500;
  options.particle_integration_share = a.particle_share;
  using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, Rule, Material, Crack>;
  PlateSolver solver(ShellModel::rectangular_plate(length, length, a.n, a.n, thickness), parameters, options);
  const ShellModel& model = solver.model();
  solver.clamp(model.set("boundary"));
  const ParticleSet all = model.all_particles();
  solver.add_uniform_pressure(all, pressure);  // pushes along −z
  const int point_a = model.set("centre")[0];
  const int stress_point_a = model.nearest_stress_point(Vector3(length / 2, length / 2, 0));
  const double spacing = length / (a.n - 1);
  const int stress_point_b = model.nearest_stress_point(Vector3(length / 2, spacing / 2, 0));

  std::vector<std::string> columns{"t [s]", "w_A [m]"};
  const int points = PlateSolver::output_points;
  for (int k = 1; k <= points; ++k) columns.push_back("sigma_eq_A_ip" + std::to_string(k) + " [Pa]");
  for (int k = 1; k <= points; ++k) columns.push_back("eps_p_A_ip" + std::to_string(k));
  for (int k = 1; k <= points; ++k) columns.push_back("sigma_eq_B_ip" + std::to_string(k) + " [Pa]");
  for (int k = 1; k <= points; ++k) columns.push_back("eps_p_B_ip" + std::to_string(k));
  for (int k = 1; k <= points; ++k) columns.push_back("D_B_ip" + std::to_string(k));
  if constexpr (Crack::enabled)
    columns.insert(columns.end(),
                   {"crack_length [m]", "longest_crack [m]", "cracks", "damaged_stress_points", "fragments"});
  const std::string csv = a.output + "/history.csv";
  std::filesystem::create_directories(a.output);
  io::CsvProbe history(csv, columns);

  std::cout << "square plate: " << model.particle_count() << " particles, " << model.stress_point_count()
            << " stress points, " << example::rule_name<Rule>() << ", " << Material::name << ", "
            << (options.nonlinear ? "nonlinear" : "linear") << " analysis, q = " << pressure
            << " Pa, dt = " << solver.time_step() << " s" << std::endl;  // before the progress lines on stderr
  double peak = 0.0, peak_time = 0.0;
  io::PlotSeries deflection{"w at the centre A", {}, {}}, crack_length{"total crack length", {}, {}};
  io::PlotSeries longest_crack{"longest crack", {}, {}, io::PlotStyle::dashed};
  // Fig. 21 follows one of the four edge cracks; the longest stands for it.
  auto longest_crack_length = [](const PlateSolver& s) {
    double longest = 0.0;
    if constexpr (Crack::enabled)
      for (double length : s.crack().crack_lengths()) longest = std::max(longest, length);
    return longest;
  };
  const auto start = std::chrono::steady_clock::now();
  solver.run_until(a.end_time, [&](const PlateSolver& s) {
    const double w = -s.displacement(point_a).z();
    if (w > peak) {
      peak = w;
      peak_time = s.time();
    }
    if (s.steps() % 5 != 0) return;
    const double longest = longest_crack_length(s);
    std::vector<double> row{s.time(), w};
    for (int k = 0; k < points; ++k) row.push_back(s.equivalent_stress(stress_point_a, k));
    for (int k = 0; k < points; ++k) row.push_back(s.equivalent_plastic_strain(stress_point_a, k));
    for (int k = 0; k < points; ++k) row.push_back(s.equivalent_stress(stress_point_b, k));
    for (int k = 0; k < points; ++k) row.push_back(s.equivalent_plastic_strain(stress_point_b, k));
    for (int k = 0; k < points; ++k) row.push_back(s.damage(stress_point_b, k));
    if constexpr (Crack::enabled)
      row.insert(row.end(), {s.crack().total_length(), longest, double(s.crack().crack_count()),
                             double(s.damaged_stress_point_count()), double(s.fragment_count())});
    history.write_row(row);
    deflection.x.push_back(s.time() * 1e3);
    deflection.y.push_back(w * 1e3);
    if constexpr (Crack::enabled) {
      crack_length.x.push_back(s.time() * 1e3);
      crack_length.y.push_back(s.crack().total_length());
      longest_crack.x.push_back(s.time() * 1e3);
      longest_crack.y.push_back(longest);
    }
  });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const EnergyReport energy = solver.energy();
  const double scale = example::energy_scale(energy);
  std::cout << "done: " << solver.steps() << " steps in " << seconds << " s ("
            << 1e6 * seconds / solver.steps() << " µs per step)\n"
            << "peak centre deflection " << peak * 1e3 << " mm at t = " << peak_time * 1e3 << " ms\n"
            << "energy at the end: kinetic " << example::shown_energy(energy.kinetic, scale) << " J, internal "
            << example::shown_energy(energy.internal, scale) << " J (plastic dissipation "
            << example::shown_energy(energy.plastic_dissipation, scale) << " J), external work "
            << example::shown_energy(energy.external_work, scale) << " J, balance " << energy.balance() << " J\n";
  if constexpr (Crack::enabled)
    std::cout << "cracks: " << solver.crack().crack_count() << " cracks, total length "
              << solver.crack().total_length() << " m (longest " << longest_crack_length(solver) << " m), "
              << solver.damaged_stress_point_count()
              << " damaged stress points, " << solver.fragment_count() << " fragment particles\n";
  if (a.analysis == "linear") {
    const double static_deflection = static_mindlin_deflection(pressure);
    const double period =
        2 * M_PI / (35.99 / (length * length) * std::sqrt(bending_stiffness / (density * thickness)));
    std::cout << "closed forms: static Mindlin deflection " << static_deflection * 1e3
              << " mm (dynamic peak ≈ twice that: " << 2e3 * static_deflection
              << " mm), fundamental period " << period * 1e3 << " ms (first peak near "
              << period * 5e2 << " ms)\n";
  }
  std::vector<io::PlotPanel> panels{{"Centre deflection (paper Figs 8, 22)", "t [ms]", "w_A [mm]", {deflection}}};
  if (a.analysis == "linear") {
    const double twice_static = 2e3 * static_mindlin_deflection(pressure);
    panels[0].series.push_back({"2 × static Mindlin deflection", {0.0, a.end_time * 1e3}, {twice_static, twice_static},
                                io::PlotStyle::dashed});
  }
  if constexpr (Crack::enabled)
    panels.push_back({"Crack length (paper Fig. 21)", "t [ms]", "crack length [m]", {crack_length, longest_crack}});
  const std::string plot = std::filesystem::path(csv).replace_extension(".svg").string();
  io::write_svg_plot(plot, panels);
  std::cout << "history written to " << csv << ", plot to " << plot << '\n';
  return 0;
}

template <class Rule>
int run_case(const Arguments& a) {
  if (a.analysis == "linear" || a.analysis == "nonlinear") return run<Rule, material::Elastic>(a, {E, nu});
  if (a.analysis == "plastic") return run<Rule, material::J2Plasticity>(a, {E, nu, sigma_y0, Ep});
  const material::LemaitreDamage::Parameters damage{E, nu, sigma_y0, Ep, eps_s, eps_c, Dc};
  if (a.analysis == "damage") return run<Rule, material::LemaitreDamage>(a, damage);
  if (a.analysis == "fracture") return run<Rule, material::LemaitreDamage, crack::LineSegments>(a, damage);
  throw Error("unknown --case " + a.analysis + " (linear, nonlinear, plastic, damage, fracture)");
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::optional<Arguments> arguments = parse(argc, argv);
    if (!arguments) return 0;
    const Arguments& a = *arguments;
    if (a.rule == "gauss5") return run_case<thickness::Gauss<5>>(a);
    if (a.rule == "gauss3") return run_case<thickness::Gauss<3>>(a);
    if (a.rule == "gauss7") return run_case<thickness::Gauss<7>>(a);
    if (a.rule == "global") return run_case<thickness::Global>(a);
    throw Error("unknown --rule " + a.rule + " (gauss5, gauss3, gauss7, global)");
  } catch (const std::exception& error) {
    std::cerr << "square_plate: " << error.what() << '\n';
    return 1;
  }
}
