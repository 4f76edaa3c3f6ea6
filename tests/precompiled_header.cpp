// Compiles nothing of its own: its object library builds the precompiled
// header that the test executables share (tests/CMakeLists.txt).
