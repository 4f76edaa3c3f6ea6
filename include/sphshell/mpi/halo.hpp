#pragma once
// The halo plan and exchange (docs/distributed.md, "The halo exchange"):
// which owned particles each rank sends to which other rank, and the
// exchange of Vector3 fields (positions and directors before the internal
// forces) into the ghosts.
//
// The plan is set up once (the rows are fixed in the reference configuration):
// each rank asks the owners of its ghosts for them, and each owner checks that
// it owns what it is asked for. The exchange then posts one receive and one
// send per neighbour rank, all fields of a call packed in one message, in the
// plan's fixed order, so the bytes a rank receives are the owner's values
// themselves (a copy: nothing is summed, nothing rounds).

#include <sphshell/core/error.hpp>
#include <sphshell/core/types.hpp>
#include <sphshell/mpi/communicator.hpp>
#include <sphshell/mpi/error_agreement.hpp>
#include <sphshell/mpi/layout.hpp>

#include <mpi.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace sphshell::mpi {

// One neighbour rank: the local indices of the owned particles sent to it and
// of the ghosts received from it, both ascending in global index.
struct HaloNeighbour {
  int rank = 0;
  std::vector<std::size_t> send, receive;
};

class HaloPlan {
 public:
  HaloPlan() = default;

  // Collective: every rank of the communicator calls it with its own layout.
  // A request for a particle the receiver does not own is an Error on every rank.
  HaloPlan(const Communicator& comm, const RankLayout& layout) {
    const auto ranks = static_cast<std::size_t>(comm.size());
    // The ghosts by owner: what this rank asks each owner for. A layout that
    // does not fit the communicator stops every rank.
    std::vector<std::vector<std::int64_t>> requests(ranks);
    std::vector<std::vector<std::size_t>> receive(ranks);
    collectively(comm, [&] {
      if (layout.rank != comm.rank())
        sphshell::detail::invalid_parameter("halo layout rank", layout.rank,
                                            "must equal the communicator's rank " + std::to_string(comm.rank()));
      for (std::size_t k = 0; k < layout.ghost_count(); ++k) {
        const int owner = layout.ghost_owner[k];
        if (owner < 0 || owner >= comm.size() || owner == comm.rank())
          sphshell::detail::invalid_parameter("owner of ghost particle " + std::to_string(layout.ghost[k]), owner,
                                              "must be another rank of the communicator");
        requests[owner].push_back(layout.ghost[k]);
        receive[owner].push_back(layout.owned_count() + k);
      }
    });
    std::vector<int> asked(ranks), asking(ranks);
    for (std::size_t r = 0; r < ranks; ++r) asked[r] = static_cast<int>(requests[r].size());
    detail::check(MPI_Alltoall(asked.data(), 1, MPI_INT, asking.data(), 1, MPI_INT, comm.get()), "MPI_Alltoall");
    std::vector<std::vector<std::int64_t>> wanted(ranks);
    std::vector<MPI_Request> pending;
    for (std::size_t r = 0; r < ranks; ++r) {
      if (asking[r] == 0) continue;
      wanted[r].resize(static_cast<std::size_t>(asking[r]));
      pending.emplace_back();
      detail::check(MPI_Irecv(wanted[r].data(), asking[r], MPI_INT64_T, static_cast<int>(r), plan_tag, comm.get(),
                              &pending.back()),
                    "MPI_Irecv");
    }
    for (std::size_t r = 0; r < ranks; ++r) {
      if (requests[r].empty()) continue;
      pending.emplace_back();
      detail::check(MPI_Isend(requests[r].data(), asked[r], MPI_INT64_T, static_cast<int>(r), plan_tag, comm.get(),
                              &pending.back()),
                    "MPI_Isend");
    }
    detail::check(MPI_Waitall(static_cast<int>(pending.size()), pending.data(), MPI_STATUSES_IGNORE), "MPI_Waitall");
    // The sends, checked: every particle asked for must be owned here.
    std::optional<Failure> failure;
    for (std::size_t r = 0; r < ranks && !failure; ++r)
      for (std::int64_t global : wanted[r]) {
        const bool valid = global >= 0 && static_cast<std::size_t>(global) < layout.local_of.size();
        const int local = valid ? layout.local_of[static_cast<std::size_t>(global)] : -1;
        if (local < 0 || static_cast<std::size_t>(local) >= layout.owned_count()) {
          failure = Failure{global, "sphshell: rank " + std::to_string(r) + " asked rank " +
                                        std::to_string(comm.rank()) + " for particle " + std::to_string(global) +
                                        ", which it does not own (the ranks' partitions differ)", nullptr};
          break;
        }
      }
    agree_on_failure(comm, failure);
    for (std::size_t r = 0; r < ranks; ++r) {
      if (wanted[r].empty() && receive[r].empty()) continue;
      HaloNeighbour neighbour;
      neighbour.rank = static_cast<int>(r);
      for (std::int64_t global : wanted[r])
        neighbour.send.push_back(static_cast<std::size_t>(layout.local_of[static_cast<std::size_t>(global)]));
      neighbour.receive = std::move(receive[r]);
      neighbours_.push_back(std::move(neighbour));
    }
    local_count_ = layout.local_count();
  }

  const std::vector<HaloNeighbour>& neighbours() const { return neighbours_; }
  std::size_t local_count() const { return local_count_; }
  std::size_t sent_particles() const {
    std::size_t count = 0;
    for (const HaloNeighbour& n : neighbours_) count += n.send.size();
    return count;
  }
  std::size_t received_particles() const {
    std::size_t count = 0;
    for (const HaloNeighbour& n : neighbours_) count += n.receive.size();
    return count;
  }
  // Bytes this rank sends in one exchange of `fields` Vector3 fields.
  std::size_t bytes_sent(std::size_t fields) const { return sent_particles() * fields * sizeof(Vector3); }

 private:
  static constexpr int plan_tag = 7301;
  std::vector<HaloNeighbour> neighbours_;
  std::size_t local_count_ = 0;
};

// The exchange of Vector3 fields over a plan; keeps its buffers between calls.
class HaloExchange {
 public:
  // Copies the owners' values of every field into this rank's ghosts.
  // Collective over the plan's neighbours. Every field has the plan's local size.
  void exchange(const Communicator& comm, const HaloPlan& plan, const std::vector<std::vector<Vector3>*>& fields) {
    for (const std::vector<Vector3>* field : fields)
      if (field == nullptr || field->size() != plan.local_count())
        sphshell::detail::invalid_parameter("halo field size", field ? field->size() : 0,
                                            "must equal the local particle count " + std::to_string(plan.local_count()));
    const std::vector<HaloNeighbour>& neighbours = plan.neighbours();
    const std::size_t components = 3 * fields.size();
    send_.resize(neighbours.size());
    receive_.resize(neighbours.size());
    requests_.assign(2 * neighbours.size(), MPI_REQUEST_NULL);
    for (std::size_t k = 0; k < neighbours.size(); ++k) {
      receive_[k].resize(neighbours[k].receive.size() * components);
      if (!receive_[k].empty())
        detail::check(MPI_Irecv(receive_[k].data(), static_cast<int>(receive_[k].size()), MPI_DOUBLE,
                                neighbours[k].rank, exchange_tag, comm.get(), &requests_[k]),
                      "MPI_Irecv");
    }
    for (std::size_t k = 0; k < neighbours.size(); ++k) {
      std::vector<double>& buffer = send_[k];
      buffer.resize(neighbours[k].send.size() * components);
      std::size_t at = 0;
      for (const std::vector<Vector3>* field : fields)
        for (std::size_t local : neighbours[k].send)
          for (int c = 0; c < 3; ++c) buffer[at++] = (*field)[local][c];
      if (!buffer.empty())
        detail::check(MPI_Isend(buffer.data(), static_cast<int>(buffer.size()), MPI_DOUBLE, neighbours[k].rank,
                                exchange_tag, comm.get(), &requests_[neighbours.size() + k]),
                      "MPI_Isend");
    }
    detail::check(MPI_Waitall(static_cast<int>(requests_.size()), requests_.data(), MPI_STATUSES_IGNORE),
                  "MPI_Waitall");
    for (std::size_t k = 0; k < neighbours.size(); ++k) {
      std::size_t at = 0;
      for (std::vector<Vector3>* field : fields)
        for (std::size_t local : neighbours[k].receive)
          for (int c = 0; c < 3; ++c) (*field)[local][c] = receive_[k][at++];
    }
  }

 private:
  static constexpr int exchange_tag = 7302;
  std::vector<std::vector<double>> send_, receive_;
  std::vector<MPI_Request> requests_;
};

}  // namespace sphshell::mpi
