#pragma once
// What solve_static's dynamic relaxation needs from the domain part
// (domain/domain.hpp) to run over a distributed share as it runs on one
// process, to the last bit:
//
//  - sums over the degrees of freedom (norms, the damping's products) are
//    exact sums (core/exact_sum.hpp: the correctly rounded total, the same for
//    any split), rounded once after the reduction;
//  - each process relaxes its owned particles; the ghosts take their owners'
//    positions, directors and free directions by the halo exchange;
//  - the fictitious masses sum each row of the tangent in the global order of
//    its columns (a ghost column lands where the one process has it);
//  - the free rigid-body modes are looked for on the whole model (each
//    process gathers it once, at the start of a solve).
//
// The one-process run is the case with no ghosts: every sum is the same
// exact sum, every order the global one.

#include <sphshell/core/types.hpp>
#include <sphshell/core/exact_sum.hpp>

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

namespace sphshell::statics::detail {

// The exact sum of a ∘ b over the free degrees of freedom of every process
// (collective in a distributed run).
template <class Domain>
double global_dot(const Domain& domain, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  sphshell::ExactSum sum;
  for (Eigen::Index k = 0; k < a.size(); ++k) sum.add(a[k] * b[k]);
  if constexpr (Domain::is_distributed)
    return domain.totals(std::array<const sphshell::ExactSum*, 1>{&sum})[0];
  else
    return sum.value();
}

template <class Domain>
double global_norm(const Domain& domain, const Eigen::VectorXd& v) {
  return std::sqrt(global_dot(domain, v, v));
}

// The local particles in the global order (the identity on one process).
template <class Domain>
std::vector<std::size_t> in_global_order(const Domain& domain, std::size_t local_particles) {
  std::vector<std::size_t> order(local_particles);
  std::iota(order.begin(), order.end(), std::size_t{0});
  if constexpr (Domain::is_distributed)
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return domain.global_of(a) < domain.global_of(b); });
  return order;
}

// The free directions of a process's particles as per-particle fields
// (what a halo exchange and a gather carry): the three translations, the two
// rotations and the counts (n_t, n_r, 0).
struct BasisFields {
  static constexpr std::size_t count = 6;
  std::array<std::vector<Vector3>, count> field;

  template <class Basis>
  explicit BasisFields(const Basis& basis) {
    const std::size_t n = basis.translation.size();
    for (auto& f : field) f.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t t = 0; t < 3; ++t) field[t][i] = basis.translation[i][t];
      for (std::size_t r = 0; r < 2; ++r) field[3 + r][i] = basis.rotation[i][r];
      field[5][i] = Vector3(basis.translations[i], basis.rotations[i], 0.0);
    }
  }
  std::vector<std::vector<Vector3>*> pointers() {
    std::vector<std::vector<Vector3>*> all;
    for (auto& f : field) all.push_back(&f);
    return all;
  }
  template <class Basis>
  void to(Basis& basis) const {
    const std::size_t n = field[0].size();
    basis.translation.resize(n);
    basis.rotation.resize(n);
    basis.translations.resize(n);
    basis.rotations.resize(n);
    basis.offset.resize(n + 1);
    int offset = 0;
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t t = 0; t < 3; ++t) basis.translation[i][t] = field[t][i];
      for (std::size_t r = 0; r < 2; ++r) basis.rotation[i][r] = field[3 + r][i];
      basis.translations[i] = static_cast<int>(field[5][i].x());
      basis.rotations[i] = static_cast<int>(field[5][i].y());
      basis.offset[i] = offset;
      offset += basis.translations[i] + basis.rotations[i];
    }
    basis.offset[n] = offset;
    basis.size = offset;
  }
};

// The ghosts' free directions from their owners (the conditions are held by
// the owners only).
template <class Domain, class Basis>
void share_basis(Domain& domain, Basis& basis) {
  if constexpr (Domain::is_distributed) {
    BasisFields fields(basis);
    domain.exchange(fields.pointers());
    fields.to(basis);
  }
}

// The whole model's coupling graph, particles and free directions on every
// process, for the check of its free rigid-body modes (collective: gathers of
// O(N) values, once per solve).
template <class Basis>
struct WholeModel {
  struct Particles {
    std::vector<Vector3> position, director;
  } particles;
  std::vector<std::vector<int>> coupled;
  Basis basis;
};

template <class Domain, class Particles, class Basis>
WholeModel<Basis> whole_model(const Domain& domain, std::size_t particle_count,
                              const std::vector<std::vector<int>>& coupled, const Particles& particles,
                              const Basis& basis) {
  WholeModel<Basis> whole;
  std::vector<std::int64_t> pairs;
  for (std::size_t i = 0; i < domain.owned_count(); ++i)
    for (int j : coupled[i]) {
      pairs.push_back(domain.global_of(i));
      pairs.push_back(domain.global_of(static_cast<std::size_t>(j)));
    }
  const std::vector<std::int64_t> all = domain.gathered_ids(pairs);
  whole.coupled.resize(particle_count);
  // Each particle's own entry first, as coupling() lists it.
  for (std::size_t k = 0; k + 1 < all.size(); k += 2)
    if (all[k] == all[k + 1]) whole.coupled[static_cast<std::size_t>(all[k])].push_back(static_cast<int>(all[k]));
  for (std::size_t k = 0; k + 1 < all.size(); k += 2)
    if (all[k] != all[k + 1]) whole.coupled[static_cast<std::size_t>(all[k])].push_back(static_cast<int>(all[k + 1]));
  whole.particles.position = domain.gathered(particles.position);
  whole.particles.director = domain.gathered(particles.director);
  BasisFields fields(basis);
  for (auto& f : fields.field) f = domain.gathered(f);
  fields.to(whole.basis);
  return whole;
}

}  // namespace sphshell::statics::detail
