// The tests' main: Catch2's own session, with every test case also tagged by
// the file it is written in ([#test_solver_parts]; Catch's --filenames-as-tags,
// on by default here). tests/CMakeLists.txt compiles some test files together
// into one executable and registers each file's test cases under that file's
// name by selecting this tag.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

int main(int argc, char* argv[]) {
  Catch::Session session;
  if (const int error = session.applyCommandLine(argc, argv)) return error;
  session.configData().filenamesAsTags = true;
  return session.run();
}
