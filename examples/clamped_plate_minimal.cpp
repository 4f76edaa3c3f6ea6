// The README's complete program ("A complete program") with a command line
// around it: the paper's clamped plate (§3, Table 3), elastoplastic, centre
// deflection after 2 ms (Fig. 15).
// `clamped_plate_minimal --help` lists the option and the files written.
#include <sphshell/sphshell.hpp>
#include <iostream>

#include "example_arguments.hpp"

int main(int argc, char** argv) try {
  using namespace sphshell;
  std::string output = "clamped_plate_minimal";
  example::CommandLine command_line("clamped_plate_minimal",
                                    "The README's complete program: the paper's clamped 0.5 m steel plate, "
                                    "elastoplastic and geometrically nonlinear, under a 1 MPa step pressure.");
  command_line.output_folder(output);
  command_line.writes("centre.csv", "every step: the centre particle's displacement, velocity and rotation");
  command_line.writes("particles.pvd, stress_points.pvd", "ParaView frames of particles and stress points");
  if (!command_line.parse(argc, argv)) return 0;

  using PlateSolver = Solver<approx::MLS<kernel::CubicSpline>, thickness::Gauss<5>,
                             material::J2Plasticity, crack::None>;
  // 0.5 m × 0.5 m × 10 mm steel plate, 51 × 51 particles (2500 stress points).
  ShellModel plate = ShellModel::rectangular_plate(0.5, 0.5, 51, 51, 0.01);
  material::J2Plasticity::Parameters steel{210e9, 0.3, 235e6, 0.0};  // E, ν, σs0, Ep (SI)
  SolverOptions options;
  options.density = 7850.0;
  options.nonlinear = true;             // geometrically nonlinear (Green strain)
  options.output_directory = output;    // ParaView: <output>/particles.pvd
  options.output_interval = 2e-4;       // s
  PlateSolver solver(plate, steel, options);
  solver.clamp(plate.set("boundary"));
  const ParticleSet all = plate.all_particles();
  solver.add_uniform_pressure(all, 1e6, time_function::Step{});  // 1 MPa step load
  const int centre = plate.set("centre")[0];
  solver.add_particle_probe(output + "/centre.csv", centre);
  solver.run_until(2e-3, [&](const PlateSolver& s) {
    if (s.steps() % 500 == 0)
      std::clog << "t = " << s.time() << " s  w = " << s.displacement(centre).z() << " m\n";
  });
  std::cout << "centre deflection at 2 ms: " << solver.displacement(centre).z() * 1e3 << " mm, "
            << solver.steps() << " steps\n";
  return 0;
} catch (const std::exception& error) {
  std::cerr << "clamped_plate_minimal: " << error.what() << '\n';
  return 1;
}
