// Catch2 under MPI: every rank runs every test case in the same order (the
// cases call collectives), and reports its own failures; mpirun fails when
// any rank does. The cases use CHECK, never REQUIRE: a rank that left a case
// early would leave the others waiting in its collectives. Every case is also
// tagged by its file ([#test_mpi_solver]: Catch's --filenames-as-tags, on by
// default here), which selects one file's cases from a group's program
// (tests/mpi/CMakeLists.txt).
#define CATCH_CONFIG_RUNNER
#include <sphshell/mpi/communicator.hpp>

#include <catch2/catch.hpp>

int main(int argc, char** argv) {
  sphshell::mpi::Environment environment(argc, argv);
  Catch::Session session;
  if (const int error = session.applyCommandLine(argc, argv)) return error;
  session.configData().filenamesAsTags = true;
  return session.run();
}
