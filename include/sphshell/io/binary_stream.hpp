#pragma once
// A small binary serialisation for checkpoints (solver/checkpoint.hpp): a
// writer that appends values to a byte buffer and a reader that takes them
// back, both in one fixed byte order (little endian, whatever the machine), so
// a file means the same on every platform.
//
// What can be written and read:
//   - bool (one byte, 0 or 1), integers and enums (their width, little
//     endian), float and double (their IEEE-754 bits, so every value, NaN
//     payloads included, comes back bit for bit);
//   - Eigen fixed-size matrices of those (coefficients in storage order);
//   - std::string, std::vector and std::array of writable values (a vector and
//     a string carry their length as 64 bits first);
//   - a type that lists its fields through a static member
//       template <class S, class F> static void for_each_field(S& self, F&& field)
//       { field(self.a, self.b, self.c); }
//     (S is T or const T), e.g. a material law's State. Listing the fields
//     keeps the file independent of the compiler's padding and layout.
// writer(a, b, c) writes a, b and c in order; reader(a, b, c) reads them back.
//
// Sections: begin_section("PART") … end_section() frame a part's data with a
// four-letter tag and its size; the reader's open_section/close_section check
// the tag and that the part read exactly its bytes, so a part that reads more
// or less than it wrote is caught at its own section, by name.
//
// FNV-1a (64 bit) is the checksum: a few lines, no dependency, and any single
// changed byte changes it.

#include <sphshell/core/error.hpp>

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace sphshell::io {

inline constexpr std::uint64_t fnv1a_offset_basis = 14695981039346656037ull;
inline constexpr std::uint64_t fnv1a_prime = 1099511628211ull;

// FNV-1a over n bytes, continuing from hash (the offset basis to start).
inline std::uint64_t fnv1a(const void* data, std::size_t n, std::uint64_t hash = fnv1a_offset_basis) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) {
    hash ^= bytes[i];
    hash *= fnv1a_prime;
  }
  return hash;
}
inline std::uint64_t fnv1a(const std::string& text, std::uint64_t hash = fnv1a_offset_basis) {
  return fnv1a(text.data(), text.size(), hash);
}

namespace detail {

template <class T, class = void>
struct has_for_each_field : std::false_type {};
// Probed with a callable taking anything.
struct AnyFields {
  template <class... Fields>
  void operator()(Fields&&...) const {}
};
template <class T>
struct has_for_each_field<T, std::void_t<decltype(T::for_each_field(std::declval<T&>(), AnyFields{}))>>
    : std::true_type {};

template <class T>
struct is_fixed_eigen : std::false_type {};
template <class Scalar, int Rows, int Columns, int Options, int MaxRows, int MaxColumns>
struct is_fixed_eigen<Eigen::Matrix<Scalar, Rows, Columns, Options, MaxRows, MaxColumns>>
    : std::bool_constant<(Rows > 0 && Columns > 0)> {};

template <class T>
struct is_std_vector : std::false_type {};
template <class T, class A>
struct is_std_vector<std::vector<T, A>> : std::true_type {};

template <class T>
struct is_std_array : std::false_type {};
template <class T, std::size_t N>
struct is_std_array<std::array<T, N>> : std::true_type {};

template <class T>
inline constexpr bool is_scalar_value_v = std::is_arithmetic_v<T> || std::is_enum_v<T>;

// long and std::size_t change width between platforms: they, and every 8-byte
// integer, are stored as 64 bits; narrower integers in their own width.
template <class T>
inline constexpr bool is_wide_integer_v = sizeof(T) == 8 || std::is_same_v<T, long> ||
                                          std::is_same_v<T, unsigned long>;
template <class T>
using stored_unsigned_t =
    std::conditional_t<is_wide_integer_v<T>, std::uint64_t, std::make_unsigned_t<T>>;

}  // namespace detail

// Whether BinaryWriter and BinaryReader handle T (see the header comment).
template <class T>
constexpr bool is_serialisable() {
  if constexpr (detail::is_scalar_value_v<T> || std::is_same_v<T, std::string>) {
    return true;
  } else if constexpr (detail::is_fixed_eigen<T>::value) {
    return detail::is_scalar_value_v<typename T::Scalar>;
  } else if constexpr (detail::is_std_vector<T>::value || detail::is_std_array<T>::value) {
    return is_serialisable<typename T::value_type>();
  } else {
    return detail::has_for_each_field<T>::value;
  }
}

class BinaryWriter {
 public:
  template <class... Values>
  void operator()(const Values&... values) {
    (write(values), ...);
  }

  template <class T>
  void write(const T& value) {
    static_assert(is_serialisable<T>(),
                  "sphshell checkpoint: this type cannot be written; give it `template <class S, class F> static "
                  "void for_each_field(S& self, F&& field) { field(self.a, self.b); }` listing every field "
                  "(io/binary_stream.hpp)");
    if constexpr (std::is_same_v<T, bool>) {
      bytes_.push_back(value ? '\1' : '\0');
    } else if constexpr (std::is_enum_v<T>) {
      write(static_cast<std::underlying_type_t<T>>(value));
    } else if constexpr (std::is_floating_point_v<T>) {
      using Bits = std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t>;
      static_assert(sizeof(T) == sizeof(Bits), "sphshell checkpoint: float and double must be IEEE-754 binary32/64");
      Bits bits;
      std::memcpy(&bits, &value, sizeof bits);
      write_unsigned(bits);
    } else if constexpr (std::is_integral_v<T>) {
      using Stored = detail::stored_unsigned_t<T>;
      if constexpr (std::is_signed_v<T>)
        write_unsigned(static_cast<Stored>(static_cast<std::int64_t>(value)));
      else
        write_unsigned(static_cast<Stored>(value));
    } else if constexpr (std::is_same_v<T, std::string>) {
      write_size(value.size());
      bytes_.append(value);
    } else if constexpr (detail::is_fixed_eigen<T>::value) {
      for (Eigen::Index k = 0; k < value.size(); ++k) write(value.data()[k]);
    } else if constexpr (detail::is_std_vector<T>::value) {
      write_size(value.size());
      for (const auto& element : value) write(static_cast<const typename T::value_type&>(element));
    } else if constexpr (detail::is_std_array<T>::value) {
      for (const auto& element : value) write(element);
    } else {
      T::for_each_field(value, *this);
    }
  }

  void write_size(std::size_t n) { write(static_cast<std::uint64_t>(n)); }
  void write_raw(const void* data, std::size_t n) { bytes_.append(static_cast<const char*>(data), n); }

  // A section: four-letter tag, 64-bit size (filled in by end_section), data.
  void begin_section(const char (&tag)[5]) {
    write_raw(tag, 4);
    open_.push_back(bytes_.size());
    write(std::uint64_t{0});
  }
  void end_section() {
    const std::size_t size_at = open_.back();
    open_.pop_back();
    const std::uint64_t size = bytes_.size() - size_at - 8;
    for (int b = 0; b < 8; ++b) bytes_[size_at + std::size_t(b)] = static_cast<char>((size >> (8 * b)) & 0xffu);
  }

  const std::string& bytes() const { return bytes_; }
  std::size_t size() const { return bytes_.size(); }

 private:
  template <class Unsigned>
  void write_unsigned(Unsigned value) {
    for (std::size_t b = 0; b < sizeof(Unsigned); ++b)
      bytes_.push_back(static_cast<char>((static_cast<std::uint64_t>(value) >> (8 * b)) & 0xffu));
  }

  std::string bytes_;
  std::vector<std::size_t> open_;
};

// Reads what a BinaryWriter wrote. Every failure is an Error starting
// "sphshell: <source>: " (the file, as the checkpoint reader names it).
class BinaryReader {
 public:
  BinaryReader(std::string bytes, std::string source, std::size_t begin = 0)
      : bytes_(std::move(bytes)), source_(std::move(source)), position_(begin), end_(bytes_.size()) {}

  template <class... Values>
  void operator()(Values&... values) {
    (read(values), ...);
  }

  template <class T>
  void read(T& value) {
    static_assert(is_serialisable<T>(),
                  "sphshell checkpoint: this type cannot be read; give it `template <class S, class F> static "
                  "void for_each_field(S& self, F&& field) { field(self.a, self.b); }` listing every field "
                  "(io/binary_stream.hpp)");
    if constexpr (std::is_same_v<T, bool>) {
      const unsigned char byte = take(1)[0];
      if (byte > 1) fail("a flag holds " + std::to_string(byte) + " (0 or 1 expected) at byte " + std::to_string(position_ - 1));
      value = byte != 0;
    } else if constexpr (std::is_enum_v<T>) {
      std::underlying_type_t<T> raw{};
      read(raw);
      value = static_cast<T>(raw);
    } else if constexpr (std::is_floating_point_v<T>) {
      using Bits = std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t>;
      const Bits bits = read_unsigned<Bits>();
      std::memcpy(&value, &bits, sizeof bits);
    } else if constexpr (std::is_integral_v<T>) {
      using Stored = detail::stored_unsigned_t<T>;
      const Stored stored = read_unsigned<Stored>();
      if constexpr (std::is_signed_v<T> && sizeof(Stored) == 8) {
        const auto wide = static_cast<std::int64_t>(stored);
        if (wide < static_cast<std::int64_t>(std::numeric_limits<T>::min()) ||
            wide > static_cast<std::int64_t>(std::numeric_limits<T>::max()))
          fail("a count of " + std::to_string(wide) + " does not fit this platform's integer");
        value = static_cast<T>(wide);
      } else if constexpr (sizeof(Stored) == 8) {
        if (stored > static_cast<std::uint64_t>(std::numeric_limits<T>::max()))
          fail("a count of " + std::to_string(stored) + " does not fit this platform's integer");
        value = static_cast<T>(stored);
      } else {
        value = static_cast<T>(stored);
      }
    } else if constexpr (std::is_same_v<T, std::string>) {
      const std::size_t n = read_size(1, "text");
      const unsigned char* data = take(n);
      value.assign(reinterpret_cast<const char*>(data), n);
    } else if constexpr (detail::is_fixed_eigen<T>::value) {
      for (Eigen::Index k = 0; k < value.size(); ++k) read(value.data()[k]);
    } else if constexpr (detail::is_std_vector<T>::value) {
      const std::size_t n = read_size(1, "list");
      value.resize(n);
      for (std::size_t k = 0; k < n; ++k) {
        typename T::value_type element{};
        read(element);
        value[k] = std::move(element);
      }
    } else if constexpr (detail::is_std_array<T>::value) {
      for (auto& element : value) read(element);
    } else {
      T::for_each_field(value, *this);
    }
  }

  // A vector whose length is fixed by this side (the model's particle count,
  // say): the file must hold exactly as many, else an Error naming `what`.
  template <class T, class A>
  void read_exact(std::vector<T, A>& value, const std::string& what) {
    // The count first, so a file of another size is refused before anything
    // is read; then the entries straight into `value`, so that a large array
    // is not held twice while it loads.
    const std::size_t n = read_size(1, "list");
    if (n != value.size())
      fail(what + ": the file holds " + std::to_string(n) + " entries, this solver has " +
           std::to_string(value.size()));
    for (auto& element : value) read(element);
  }

  // A 64-bit count, checked against the bytes left (each item takes at
  // least min_item_bytes), so a damaged count cannot ask for a huge allocation.
  std::size_t read_size(std::size_t min_item_bytes, const char* what) {
    const std::uint64_t n = read_unsigned<std::uint64_t>();
    if (min_item_bytes > 0 && n > (end_ - position_) / min_item_bytes)
      fail(std::string("a ") + what + " of " + std::to_string(n) + " entries runs past the end of its section");
    return static_cast<std::size_t>(n);
  }

  void open_section(const char (&tag)[5]) {
    const unsigned char* found = take(4);
    if (std::memcmp(found, tag, 4) != 0)
      fail(std::string("section '") + tag + "' expected, found '" +
           printable(std::string(reinterpret_cast<const char*>(found), 4)) + "'");
    const std::uint64_t size = read_unsigned<std::uint64_t>();
    if (size > end_ - position_)
      fail(std::string("section '") + tag + "' of " + std::to_string(size) + " bytes runs past the end of the file");
    sections_.push_back({std::string(tag), end_});
    end_ = position_ + static_cast<std::size_t>(size);
  }
  void close_section() {
    const OpenSection section = sections_.back();
    if (position_ != end_)
      fail("section '" + section.tag + "': " + std::to_string(end_ - position_) +
           " bytes were left unread (written by another layout of this part)");
    sections_.pop_back();
    end_ = section.outer_end;
  }

  bool at_end() const { return position_ == end_; }
  // The bytes, taken away (the reader is empty after).
  std::string release_bytes() {
    position_ = end_ = 0;
    return std::move(bytes_);
  }
  std::size_t position() const { return position_; }
  const std::string& source() const { return source_; }

  [[noreturn]] void fail(const std::string& what) const {
    std::string where = source_;
    if (!sections_.empty()) where += ", section '" + sections_.back().tag + "'";
    throw Error("sphshell: " + where + ": " + what);
  }

  static std::string printable(const std::string& text) {
    std::string shown;
    for (const char c : text) shown += (c >= 32 && c < 127) ? c : '?';
    return shown;
  }

 private:
  struct OpenSection {
    std::string tag;
    std::size_t outer_end;
  };

  const unsigned char* take(std::size_t n) {
    if (n > end_ - position_)
      fail("ends after " + std::to_string(end_ - position_) + " more bytes where " + std::to_string(n) +
           " were needed");
    const auto* data = reinterpret_cast<const unsigned char*>(bytes_.data()) + position_;
    position_ += n;
    return data;
  }
  template <class Unsigned>
  Unsigned read_unsigned() {
    const unsigned char* data = take(sizeof(Unsigned));
    std::uint64_t value = 0;
    for (std::size_t b = 0; b < sizeof(Unsigned); ++b) value |= static_cast<std::uint64_t>(data[b]) << (8 * b);
    return static_cast<Unsigned>(value);
  }

  std::string bytes_;
  std::string source_;
  std::size_t position_;
  std::size_t end_;
  std::vector<OpenSection> sections_;
};

}  // namespace sphshell::io
