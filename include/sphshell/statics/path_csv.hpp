#pragma once
// An equilibrium path as CSV: a PathFollower observer (PathFollower::observe)
// writing one header line with the units, then one row per converged point.
// Each row is flushed as it is written (io::CsvProbe), so a run that is killed
// or fails leaves a valid file holding every point converged before it. The
// file is an append-only log, written in place: not replaced atomically, a
// reader may see its last row cut short only if the process dies within that
// row's write.

#include <sphshell/io/csv_probe.hpp>
#include <sphshell/statics/path_following.hpp>

#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace sphshell::statics {

class PathCsv {
 public:
  // Opens (truncates) the file and writes the header; an Error names a file
  // that cannot be written. Copies write to the same file.
  explicit PathCsv(const std::string& path) : probe_(std::make_shared<io::CsvProbe>(path, columns())) {}

  // The columns: integers written as numbers, NaN ("nan") where a value was
  // not computed (the control under load control; the stability without
  // PathStability::compute). The eigenvalue mixes N/m and N·m/rad (statics/stability.hpp).
  static std::vector<std::string> columns() {
    return {"step",
            "load_factor [1]",
            "control (0 load 1 displacement 2 arc length)",
            "control_value [m]",
            "relative_residual [1]",
            "iterations",
            "negative_eigenvalues",
            "eigenvalue_nearest_zero [N/m or N m/rad]",
            "load_share [1]",
            "event (0 none 1 limit point 2 bifurcation)"};
  }

  void operator()(const PathPoint& point) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    probe_->write_row({static_cast<double>(point.step), point.load_factor, static_cast<double>(point.control),
                       point.control_value, point.relative_residual, static_cast<double>(point.iterations),
                       point.negative_eigenvalues >= 0 ? static_cast<double>(point.negative_eigenvalues) : nan,
                       point.eigenvalue_nearest_zero, point.load_share, static_cast<double>(point.event)});
  }

  const std::string& path() const { return probe_->path(); }

 private:
  std::shared_ptr<io::CsvProbe> probe_;
};

}  // namespace sphshell::statics
