#pragma once
// How a .vtu file stores its arrays: the encoding and the floating-point
// precision. A header of its own so that the solver's options can name them
// without bringing in the writer (and zlib).
//
// zlib compression needs zlib at link time: the CMake target sphshell::sphshell
// and the pkg-config file define SPHSHELL_HAVE_ZLIB and link zlib when the
// library was configured with it (Debian zlib1g-dev); a program compiled
// against the headers alone defines SPHSHELL_HAVE_ZLIB itself and links -lz, or
// does without compression.

namespace sphshell::io {

enum class VtuEncoding {
  // Numbers as decimal text inside the XML: large and slow, but readable with
  // a text editor (for debugging a writer or a reader).
  ascii,
  // Raw bytes in one appended section: no encoding cost, every value exact.
  binary,
  // As binary, each array deflated with zlib in blocks (VTK's
  // vtkZLibDataCompressor): ParaView and VTK read it natively.
  zlib,
};

enum class VtuPrecision {
  // Single precision: half the bytes, 7 significant digits, which is plenty
  // for looking at a field (a colour map resolves 256 levels).
  float32,
  // Double precision: the solver's numbers bit for bit, for post-processing.
  float64,
};

#ifdef SPHSHELL_HAVE_ZLIB
inline constexpr bool vtu_zlib_available = true;
#else
inline constexpr bool vtu_zlib_available = false;
#endif

inline const char* to_string(VtuEncoding encoding) {
  switch (encoding) {
    case VtuEncoding::ascii: return "ascii";
    case VtuEncoding::binary: return "binary";
    case VtuEncoding::zlib: return "zlib";
  }
  return "(not a VtuEncoding)";
}

inline const char* to_string(VtuPrecision precision) {
  switch (precision) {
    case VtuPrecision::float32: return "float32";
    case VtuPrecision::float64: return "float64";
  }
  return "(not a VtuPrecision)";
}

// What write_vtu_* produce when not told otherwise: exact raw doubles.
struct VtuFormat {
  VtuEncoding encoding = VtuEncoding::binary;
  VtuPrecision precision = VtuPrecision::float64;
};

}  // namespace sphshell::io
