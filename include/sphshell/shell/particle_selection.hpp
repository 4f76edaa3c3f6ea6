#pragma once
// The particles a condition, load or probe acts on: particle ids
// (a ParticleSet, or a braced list such as {3, 7}), or the name of one of the
// model's sets (ShellModel::add_set, a mesh file's node set). The solvers take
// either wherever they take a set; a name the model does not have is an Error
// naming it.

#include <sphshell/shell/cell.hpp>
#include <sphshell/shell/model.hpp>

#include <initializer_list>
#include <string>
#include <utility>

namespace sphshell {

class ParticleSelection {
 public:
  ParticleSelection(ParticleSet ids) : ids_(std::move(ids)) {}
  ParticleSelection(std::initializer_list<int> ids) : ids_(ids) {}
  ParticleSelection(std::string set_name) : name_(std::move(set_name)), named_(true) {}
  ParticleSelection(const char* set_name) : name_(set_name), named_(true) {}

  // The ids: the named set's members in the model, or the ids as given.
  ParticleSet members(const ShellModel& model) const { return named_ ? model.set(name_) : ids_; }
  bool is_named() const { return named_; }
  const std::string& name() const { return name_; }

 private:
  ParticleSet ids_;
  std::string name_;
  bool named_ = false;
};

}  // namespace sphshell
