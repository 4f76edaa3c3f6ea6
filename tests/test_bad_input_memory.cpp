// Memory: a model too large for the memory the process may take is
// refused up front with the estimate, and an allocation that fails anyway
// leaves the API as a sphshell::Error naming the size, never std::bad_alloc
// (nor std::terminate from inside an OpenMP region).
//
// The limit is the address-space limit (ulimit -v), set here for the test's
// own process and restored after; AddressSanitizer reserves terabytes of
// address space for its shadow memory, so these cases are skipped under it.
#include "bad_input_support.hpp"

#include <sys/resource.h>

#include <fstream>

using namespace bad_input;

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool address_sanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool address_sanitizer = true;
#else
constexpr bool address_sanitizer = false;
#endif
#else
constexpr bool address_sanitizer = false;
#endif

double address_space_in_use() {
  std::ifstream in("/proc/self/statm");
  double pages = 0.0;
  in >> pages;
  return pages * static_cast<double>(sysconf(_SC_PAGESIZE));
}

// Limits the address space to what is in use plus `headroom` bytes while alive.
class AddressSpaceLimit {
 public:
  explicit AddressSpaceLimit(double headroom) {
    getrlimit(RLIMIT_AS, &saved_);
    rlimit limit = saved_;
    limit.rlim_cur = static_cast<rlim_t>(address_space_in_use() + headroom);
    REQUIRE(setrlimit(RLIMIT_AS, &limit) == 0);
  }
  ~AddressSpaceLimit() { setrlimit(RLIMIT_AS, &saved_); }

 private:
  rlimit saved_{};
};

}  // namespace

TEST_CASE("A plate too large for the memory available is refused with the estimate", "[bad_input][memory]") {
  if (address_sanitizer) return;
  ShellModel model = ShellModel::rectangular_plate(1.0, 1.0, 1000, 1000, 0.001);
  const double mib = 1024.0 * 1024.0;
  std::string message;
  {
    const AddressSpaceLimit limit(512 * mib);
    message = error_of([&] { ElasticSolver(std::move(model), steel); });
  }
  INFO(message);
  CHECK(message.find("model too large for the memory available") != std::string::npos);
  CHECK(message.find("1000000 particles and 998001 stress points needs about") != std::string::npos);
  CHECK(message.find("neighbour slots") != std::string::npos);
  CHECK(message.find("available") != std::string::npos);
}

TEST_CASE("An allocation failure in the shape-function build is a sphshell::Error with the size",
          "[bad_input][memory]") {
  if (address_sanitizer) return;
  // 10⁴ particles and a support over all of them: 10⁸ slots, 2.8 GB of shape functions.
  std::vector<Vector3> particles;
  std::vector<double> volumes;
  std::vector<TangentFrame> frames;
  for (int j = 0; j < 100; ++j)
    for (int i = 0; i < 100; ++i) {
      particles.emplace_back(0.01 * i, 0.01 * j, 0.0);
      volumes.push_back(1e-4);
      frames.push_back(tangent_frame(Vector3::UnitZ()));
    }
  std::string message;
  {
    const AddressSpaceLimit limit(256 * 1024.0 * 1024.0);
    message = error_of([&] { approx::MLS<kernel::CubicSpline>::build(particles, volumes, particles, frames, 1.0); });
  }
  INFO(message);
  CHECK(message.find("out of memory building the shape functions of 10000 evaluation points") != std::string::npos);
  CHECK(message.find("std::bad_alloc") != std::string::npos);
  CHECK(message.find("available") != std::string::npos);
}
