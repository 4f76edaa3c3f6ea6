#pragma once
// Command lines of the examples. Each option is declared once, bound to the
// variable it sets, with its unit and meaning; the variable's value at
// declaration is the default. --help is printed from that same table, so the
// help cannot drift from what is parsed. A malformed value ("abc", "1e-3x",
// "nan"), a missing value, an unknown option or a stray argument is an Error
// naming it, never silently ignored or truncated. Once the arguments are
// accepted, the run's first line of output names the library version and the
// instruction set the example was compiled for (build_line()).

#include <sphshell/core/error.hpp>
#include <sphshell/core/simd.hpp>
#include <sphshell/version.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace sphshell::example {

inline double parse_number(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(value))
    throw Error(option + " = '" + text + "' is not a finite number");
  return value;
}

inline int parse_integer(const std::string& option, const std::string& text) {
  std::size_t used = 0;
  long value = 0;
  try {
    value = std::stol(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || value < std::numeric_limits<int>::min() ||
      value > std::numeric_limits<int>::max())
    throw Error(option + " = '" + text + "' is not an integer");
  return static_cast<int>(value);
}

// SolverOptions::particle_integration_share from the command line, checked
// here so that the error names the option rather than the solver field.
inline double parse_particle_share(const std::string& option, const std::string& text) {
  const double share = parse_number(option, text);
  if (!(share >= 0.0 && share < 1.0)) detail::invalid_parameter(option, share, "must lie in [0, 1)");
  return share;
}

// The shortest decimal that reads back as the same double, with a compact
// exponent ("0.004", "1e6", "5e-5"): defaults shown as a user would type them.
inline std::string format_number(double value) {
  constexpr int max_significant_digits = std::numeric_limits<double>::max_digits10;
  char buffer[64];
  int digits = 1;
  for (; digits <= max_significant_digits; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, value);
    if (std::strtod(buffer, nullptr) == value) break;
  }
  // 400, not 4e2: below a million, keep every digit of the integer part.
  constexpr double fixed_below = 1e6;
  if (std::abs(value) >= 1.0 && std::abs(value) < fixed_below) {
    const int integer_digits = static_cast<int>(std::floor(std::log10(std::abs(value)))) + 1;
    std::snprintf(buffer, sizeof buffer, "%.*g", std::max(digits, integer_digits), value);
  }
  std::string text = buffer;
  const std::size_t e = text.find('e');
  if (e == std::string::npos) return text;
  const std::string exponent = text.substr(e + 1);
  const bool negative = exponent.front() == '-';
  std::size_t first = exponent.front() == '-' || exponent.front() == '+' ? 1 : 0;
  while (first + 1 < exponent.size() && exponent[first] == '0') ++first;
  return text.substr(0, e) + "e" + (negative ? "-" : "") + exponent.substr(first);
}

// A thickness rule as the solver type spells it: "Gauss<5>", "Simpson<3>",
// "Global" (a resultant rule has no points).
template <class Rule>
std::string rule_name() {
  if constexpr (Rule::num_points > 0)
    return std::string(Rule::name) + "<" + std::to_string(Rule::num_points) + ">";
  else
    return Rule::name;
}

// Energies as printed. The energy ledger sums a contribution per particle and
// step in double precision (relative error ε ≈ 2.2e-16 each); over 10^4 steps
// and 10^3 particles that is ~1e-9 of the energy scale in the worst case, far
// below it in practice. A book that is zero in exact arithmetic (the plastic
// dissipation of an elastic run, say) then shows as -3.55e-15 J, a sign that
// means nothing. Printed values whose size is below energy_round_off times
// the run's energy scale (the largest of the books, from energy_scale) are
// printed as 0; the balance is printed as it is, being the ledger's error.
inline constexpr double energy_round_off = 1e-12;
template <class Energies>
double energy_scale(const Energies& energies) {
  return std::max({std::abs(energies.kinetic), std::abs(energies.internal), std::abs(energies.external_work)});
}
inline double shown_energy(double value, double scale) {
  return std::abs(value) < energy_round_off * scale ? 0.0 : value;
}

// The first line every example prints: what built it, so that a printed
// figure can be traced to its code ("#" keeps a CSV on standard output
// readable). The set in use comes from the compiler; the configured one from
// SPHSHELL_SIMD through the sphshell::sphshell target (NONE leaves the
// compiler's default, SSE2 on x86-64).
inline std::string build_line() {
  return std::string("# sphshell ") + SPHSHELL_VERSION_STRING + ", instruction set " + simd::instruction_set() +
         " (SPHSHELL_SIMD: " + simd::configured_instruction_set() + ")";
}

// The options of one example, its --help text and the parse.
class CommandLine {
 public:
  CommandLine(std::string program, std::string summary)
      : program_(std::move(program)), summary_(std::move(summary)) {}

  // A real number. unit: "s", "m", "Pa", ...; "-" for a dimensionless one.
  void number(const std::string& name, double& target, const std::string& unit, const std::string& description) {
    add({name, "X", unit, format_number(target), description,
         [&target, name](const std::string& text) { target = parse_number(name, text); }});
  }
  void integer(const std::string& name, int& target, const std::string& description) {
    add({name, "N", "", std::to_string(target), description,
         [&target, name](const std::string& text) { target = parse_integer(name, text); }});
  }
  // One of a fixed list of words; anything else is an Error listing them.
  void choice(const std::string& name, std::string& target, std::vector<std::string> choices,
              const std::string& description) {
    std::string list;
    for (const std::string& choice : choices) list += (list.empty() ? "" : "|") + choice;
    add({name, list, "", target, description, [&target, name, choices, list](const std::string& text) {
           if (std::find(choices.begin(), choices.end(), text) == choices.end())
             throw Error("unknown " + name + " " + text + " (one of " + list + ")");
           target = text;
         }});
  }
  // The folder every output file goes into (created if missing).
  void output_folder(std::string& target) {
    add({"--output", "DIR", "", target, "folder for every file the run writes, created if missing",
         [&target](const std::string& text) {
           if (text.empty()) throw Error("--output needs a folder name, not an empty string");
           target = text;
         }});
  }
  // On when given, off by default.
  void flag(const std::string& name, bool& target, const std::string& description) {
    Option option{name, "", "", target ? "on" : "off", description, {}};
    option.flag = &target;
    add(std::move(option));
  }
  // Anything else: the caller converts and checks the text, and says what the default is.
  void custom(const std::string& name, const std::string& placeholder, const std::string& unit,
              const std::string& default_text, const std::string& description,
              std::function<void(const std::string&)> set) {
    add({name, placeholder, unit, default_text, description, std::move(set)});
  }
  // A file the run writes, relative to the output folder.
  void writes(const std::string& file, const std::string& description) { outputs_.push_back({file, description}); }
  // A closing paragraph of the help.
  void note(const std::string& paragraph) { notes_.push_back(paragraph); }

  // Applies argv to the bound variables. Returns false when --help was asked
  // for: the help is then on stdout and the program should exit with 0.
  // Otherwise build_line() is printed, the run's first line.
  bool parse(int argc, char** argv) const {
    for (int k = 1; k < argc; ++k) {
      std::string name = argv[k];
      if (name == "--help" || name == "-h") {
        std::cout << help();
        return false;
      }
      std::string value;
      bool inline_value = false;
      const std::size_t equals = name.find('=');
      if (name.rfind("--", 0) == 0 && equals != std::string::npos) {
        value = name.substr(equals + 1);
        name = name.substr(0, equals);
        inline_value = true;
      }
      const auto option = std::find_if(options_.begin(), options_.end(),
                                        [&](const Option& candidate) { return candidate.name == name; });
      if (option == options_.end()) {
        if (name.rfind("-", 0) == 0)
          throw Error("unknown option " + name + " (" + program_ + " --help lists the options)");
        throw Error("unexpected argument '" + name + "' (" + program_ + " --help lists the options)");
      }
      if (option->flag) {
        if (inline_value) throw Error(name + " takes no value");
        *option->flag = true;
        continue;
      }
      if (!inline_value) {
        if (k + 1 >= argc) throw Error(name + " needs a value");
        value = argv[++k];
      }
      option->set(value);
    }
    std::cout << build_line() << '\n' << std::flush;  // first, also when the streams go to one file
    return true;
  }

  std::string help() const {
    std::ostringstream out;
    out << "Usage: " << program_ << (options_.empty() ? "" : " [options]") << "\n\n";
    out << wrap(summary_, 0, 0) << '\n';
    out << "Options:\n";
    for (const Option& option : options_) {
      const std::string label = option.name + (option.placeholder.empty() ? "" : " " + option.placeholder);
      std::string text = option.description;
      if (!option.unit.empty()) text += " [" + option.unit + "]";
      out << entry(label, text, "(default: " + option.default_text + ")");
    }
    out << entry("-h, --help", "print this help and exit", "");
    if (!outputs_.empty()) {
      out << "\nWrites, into the --output folder:\n";
      for (const auto& [file, description] : outputs_) out << entry(file, description, "");
    }
    for (const std::string& paragraph : notes_) out << '\n' << wrap(paragraph, 0, 0);
    return out.str();
  }

 private:
  struct Option {
    std::string name, placeholder, unit, default_text, description;
    std::function<void(const std::string&)> set;
    bool* flag = nullptr;
  };

  static constexpr std::size_t line_width = 79;
  static constexpr std::size_t label_indent = 2;
  static constexpr std::size_t text_column = 28;

  void add(Option option) {
    for (const Option& existing : options_)
      if (existing.name == option.name) throw Error(program_ + ": option " + option.name + " declared twice");
    options_.push_back(std::move(option));
  }

  // Words of `text` filled into lines of line_width; the first line starts at
  // column `first`, the others at `indent`. `last_word` is kept whole.
  static std::string wrap(const std::string& text, std::size_t first, std::size_t indent,
                          const std::string& last_word = "") {
    std::vector<std::string> words;
    std::istringstream stream(text);
    for (std::string word; stream >> word;) words.push_back(word);
    if (!last_word.empty()) words.push_back(last_word);
    std::string result;
    std::size_t column = first;
    bool line_empty = true;
    for (const std::string& word : words) {
      if (!line_empty && column + 1 + word.size() > line_width) {
        result += '\n' + std::string(indent, ' ');
        column = indent;
        line_empty = true;
      }
      if (!line_empty) {
        result += ' ';
        ++column;
      }
      result += word;
      column += word.size();
      line_empty = false;
    }
    return result + '\n';
  }

  static std::string entry(const std::string& label, const std::string& text, const std::string& last_word) {
    std::string line = std::string(label_indent, ' ') + label;
    if (line.size() + 1 < text_column) {
      line += std::string(text_column - line.size(), ' ');
    } else {
      line += '\n' + std::string(text_column, ' ');
    }
    return line + wrap(text, text_column, text_column, last_word);
  }

  std::string program_, summary_;
  std::vector<Option> options_;
  std::vector<std::pair<std::string, std::string>> outputs_;
  std::vector<std::string> notes_;
};

}  // namespace sphshell::example
