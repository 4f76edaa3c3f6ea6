#pragma once
// The rigid bodies of a run drawn as a .vtu grid of triangles: every body's
// surface (contact/surface_mesh.hpp) where the body is now, so that ParaView
// shows the projectile or wall beside the shell. The solver writes one such
// file per frame (bodies_N.vtu) and lists it in particles.pvd as part 1 of
// the frame's time, so opening particles.pvd opens shell and bodies together.
// The bodies are drawn where they are, whichever frame_coordinates the shell
// is drawn in.
//
// Cell data: "body" (the body's id, Solver::add_rigid_body) and
// "contact_force" (the contact force the body received in the last step, N);
// point data: "velocity" (of the body's material point there, m/s).

#include <sphshell/contact/body_set.hpp>
#include <sphshell/contact/surface_mesh.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/io/vtu_writer.hpp>

#include <string>
#include <vector>

namespace sphshell::io {

inline VtuGrid rigid_body_grid(const contact::RigidBodySet& bodies, const std::vector<Vector3>& shell_positions,
                               double time, const contact::SurfaceMeshResolution& resolution = {}) {
  VtuGrid grid;
  grid.time = time;
  grid.note = "sphshell rigid bodies: " + std::to_string(bodies.size()) + " surfaces, drawn where the bodies are";
  Field body_id{"body", 1, {}, {}, FieldValues::integer};
  Field force{"contact_force", 3, {}, {"x", "y", "z"}};
  Field velocity{"velocity", 3, {}, {"x", "y", "z"}};
  for (contact::RigidBodyId id = 0; id < bodies.size(); ++id) {
    const contact::SurfaceMesh mesh = bodies.surface(id, shell_positions, resolution);
    const contact::RigidBodyState state = bodies.state(id);
    const int first = static_cast<int>(grid.points.size());
    for (const Vector3& vertex : mesh.vertices) {
      grid.points.push_back(vertex);
      const Vector3 v =
          state.kinematics.velocity + state.kinematics.angular_velocity.cross(vertex - state.kinematics.position);
      velocity.values.insert(velocity.values.end(), {v.x(), v.y(), v.z()});
    }
    for (const auto& triangle : mesh.triangles) {
      const int corners[3] = {first + triangle[0], first + triangle[1], first + triangle[2]};
      grid.cells.add_polygon(corners, corners + 3);
      body_id.values.push_back(static_cast<double>(id));
      force.values.insert(force.values.end(),
                          {state.contact_force.x(), state.contact_force.y(), state.contact_force.z()});
    }
  }
  grid.point_fields.push_back(std::move(velocity));
  grid.cell_fields.push_back(std::move(body_id));
  grid.cell_fields.push_back(std::move(force));
  return grid;
}

}  // namespace sphshell::io
