#pragma once
// Buckling modes as ParaView frames (statics/buckling.hpp computes them): in
// the chosen folder, one buckling_mode_<k>.vtu per mode (k from 1, the
// lowest load factor first) over the shell's cells at the configuration the
// analysis started from (a model without cells: its particles as vertices),
// with the mode's translation and director rotation as point arrays;
// buckling_modes.pvd lists them with the mode's number as its time, so
// ParaView's time control steps through the modes and Warp By Vector with
// "mode_translation" draws each (the largest translation component is 1, so
// the scale is the drawn amplitude in metres); buckling_modes.csv gives each
// mode's load factor. Every file is written whole and then renamed into
// place: a run killed while writing leaves the previous files valid.

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/io/output_directory.hpp>
#include <sphshell/io/output_file.hpp>
#include <sphshell/io/pvd_collection.hpp>
#include <sphshell/io/vtu_writer.hpp>
#include <sphshell/shell/model.hpp>
#include <sphshell/statics/buckling.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace sphshell::statics {

// The grid of one mode: the cells (or vertices) over `positions`, the
// mode's translation and rotation per particle.
inline io::VtuGrid buckling_mode_grid(const ShellModel& model, const std::vector<Vector3>& positions,
                                      const BucklingMode& mode, int number) {
  io::VtuGrid grid;
  grid.points = positions;
  if (model.cells().empty()) {
    for (std::size_t i = 0; i < positions.size(); ++i) grid.cells.add_vertex(static_cast<int>(i));
  } else {
    for (const Cell& cell : model.cells()) grid.cells.add_polygon(cell.begin(), cell.end());
  }
  auto vector_field = [&](const char* name, const std::vector<Vector3>& values) {
    io::PointField field{name, 3, {}, {"x", "y", "z"}};
    field.values.reserve(3 * values.size());
    for (const Vector3& v : values) field.values.insert(field.values.end(), {v.x(), v.y(), v.z()});
    grid.point_fields.push_back(std::move(field));
  };
  vector_field("mode_translation", mode.translation);
  vector_field("mode_rotation", mode.rotation);
  grid.time = number;
  grid.note = "sphshell buckling mode " + std::to_string(number) + ": load factor " +
              io::detail::round_trip_decimal(mode.load_factor);
  return grid;
}

// Writes the modes of `result`, found from the configuration `positions` of
// `model`'s particles (Solver::positions() before the analysis), into
// `directory` (created if missing).
inline void write_buckling_modes(const std::string& directory, const ShellModel& model,
                                 const std::vector<Vector3>& positions, const BucklingResult& result,
                                 const io::VtuFormat& format = {}) {
  if (result.modes.empty())
    sphshell::detail::invalid_parameter("BucklingResult::modes", "empty", "there is no mode to write");
  if (positions.size() != model.particle_count())
    sphshell::detail::invalid_parameter("positions (buckling frames)", positions.size(),
                                        "must hold the model's " + std::to_string(model.particle_count()) +
                                            " particles");
  for (std::size_t k = 0; k < result.modes.size(); ++k)
    if (result.modes[k].translation.size() != positions.size() || result.modes[k].rotation.size() != positions.size())
      sphshell::detail::invalid_parameter("BucklingResult::modes[" + std::to_string(k) + "] size",
                                          result.modes[k].translation.size(),
                                          "must hold one translation and one rotation per particle");
  io::make_directory(directory, "", "buckling frames' folder");
  io::PvdCollection collection(directory + "/buckling_modes.pvd");
  io::detail::ReplacingOutputFile table(directory + "/buckling_modes.csv");
  table.stream() << "mode,load_factor,file\n";
  for (std::size_t k = 0; k < result.modes.size(); ++k) {
    const int number = static_cast<int>(k) + 1;
    const std::string file = "buckling_mode_" + std::to_string(number) + ".vtu";
    io::write_vtu(directory + "/" + file, buckling_mode_grid(model, positions, result.modes[k], number), format);
    collection.add(number, directory + "/" + file);
    table.stream() << number << ',' << io::detail::round_trip_decimal(result.modes[k].load_factor) << ',' << file << '\n';
  }
  table.commit();
}

}  // namespace sphshell::statics
