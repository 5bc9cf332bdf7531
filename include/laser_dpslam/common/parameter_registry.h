// One table per node of every parameter it reads: name, type, unit, allowed range, topic, a one-line
// description and whether a typical user should touch it. The readers, the check of the shipped YAML files
// and doc/parameters.md (tool parameter_docs) all come from these tables, so a key is named once; its
// default is whatever the settings struct holds when default-constructed.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "laser_dpslam/common/parameter_source.h"

namespace laser_dpslam {

/// Allowed values of a number: an interval whose ends may be open, closed or absent (infinite).
struct ParameterRange {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  bool contains(double v) const;
  /// "any", "> 0", ">= 3", "< 0", "<= 1", "[0, 1]", "(0, 1]".
  std::string text() const;
};

ParameterRange anyValue();
ParameterRange above(double lo);
ParameterRange atLeast(double lo);
ParameterRange below(double hi);
ParameterRange atMost(double hi);
ParameterRange closedInterval(double lo, double hi);
/// (lo, hi]
ParameterRange leftOpenInterval(double lo, double hi);

/// A string parameter with a fixed set of values, held as something else (an enum) in the settings.
template <class S>
struct ChoiceField {
  std::string (*get)(const S&);
  void (*set)(S&, const std::string&);  ///< throws std::invalid_argument for a value not in `choices`
  const char* choices;                  ///< for the documentation, e.g. "none, uniform"
};

enum class ParameterLevel { kUser, kAdvanced };

/// One parameter of the settings struct S. `field` gives the member the key reads into.
template <class S>
struct Parameter {
  using Field = std::variant<double& (*)(S&), int& (*)(S&), std::uint64_t& (*)(S&), bool& (*)(S&),
                             std::string& (*)(S&), std::vector<double>& (*)(S&), ChoiceField<S>>;
  const char* name;
  const char* topic;  ///< documentation group: scan, matching, ...
  Field field;
  const char* unit;
  ParameterRange range;  ///< numbers only (for a list: each element)
  const char* description;
  ParameterLevel level;

  bool advanced() const { return level == ParameterLevel::kAdvanced; }
};

/// A parameter as the documentation shows it.
struct ParameterInfo {
  std::string name, topic, type, default_value, unit, range, description;
  bool advanced = false;
};

/// Shortest decimal text that reads back as the same double ("0.25", "1.0", "-.inf" as YAML writes it).
std::string formatParameterNumber(double v);
/// Throws std::invalid_argument "parameter 'key' = value is outside its range R".
void checkParameterRange(const std::string& key, double value, const ParameterRange& range);
void checkParameterRange(const std::string& key, int value, const ParameterRange& range);

namespace detail {
template <class T>
struct Tag {};

inline std::string text(double v) { return formatParameterNumber(v); }
inline std::string text(int v) { return std::to_string(v); }
inline std::string text(std::uint64_t v) { return std::to_string(v); }
inline std::string text(bool v) { return v ? "true" : "false"; }
inline std::string text(const std::string& v) { return v; }
inline std::string text(const std::vector<double>& v) {
  std::string out = "[";
  for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + formatParameterNumber(v[i]);
  return out + "]";
}

inline const char* typeName(Tag<double>) { return "number"; }
inline const char* typeName(Tag<int>) { return "integer"; }
inline const char* typeName(Tag<std::uint64_t>) { return "integer"; }
inline const char* typeName(Tag<bool>) { return "bool"; }
inline const char* typeName(Tag<std::string>) { return "string"; }
inline const char* typeName(Tag<std::vector<double>>) { return "list of numbers"; }

template <class S, class T>
void read(const ParameterSource& source, const Parameter<S>& p, T& (*field)(S&), S& s) {
  if constexpr (std::is_same_v<T, std::uint64_t>) {
    // Seeds: the parameter server has no unsigned integers.
    int v = 0;
    if (!source.get(p.name, v)) return;
    checkParameterRange(p.name, v, p.range);
    field(s) = static_cast<std::uint64_t>(v);
  } else {
    T v{};
    if (!source.get(p.name, v)) return;
    if constexpr (std::is_same_v<T, double> || std::is_same_v<T, int>) checkParameterRange(p.name, v, p.range);
    if constexpr (std::is_same_v<T, std::vector<double>>) {
      if (v.empty()) throw std::invalid_argument("parameter '" + std::string(p.name) + "' must not be empty");
      for (double e : v) checkParameterRange(p.name, e, p.range);
    }
    field(s) = v;
  }
}

template <class S>
void read(const ParameterSource& source, const Parameter<S>& p, const ChoiceField<S>& field, S& s) {
  std::string v;
  if (!source.get(p.name, v)) return;
  try {
    field.set(s, v);
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument("parameter '" + std::string(p.name) + "' = '" + v + "': must be one of " + field.choices);
  }
}
}  // namespace detail

/// Reads one key into its member when the source holds it; throws std::invalid_argument naming the key,
/// the value and the allowed range when the value is out of range or of the wrong type.
template <class S>
void readParameter(const ParameterSource& source, const Parameter<S>& p, S& s) {
  std::visit([&](const auto& field) { detail::read(source, p, field, s); }, p.field);
}

template <class S>
void readParameters(const ParameterSource& source, const std::vector<Parameter<S>>& registry, S& s) {
  for (const Parameter<S>& p : registry) readParameter(source, p, s);
}

/// The member's value as text (lists as "[1.0, 0.5]", numbers as short as they read back exactly).
template <class S>
std::string parameterValueText(const Parameter<S>& p, S s) {
  return std::visit(
      [&](const auto& field) -> std::string {
        if constexpr (std::is_same_v<std::decay_t<decltype(field)>, ChoiceField<S>>) {
          return field.get(s);
        } else {
          return detail::text(field(s));
        }
      },
      p.field);
}

/// The entry as doc/parameters.md shows it, with the default of a default-constructed S.
template <class S>
ParameterInfo describeParameter(const Parameter<S>& p) {
  ParameterInfo info;
  info.name = p.name;
  info.topic = p.topic;
  info.default_value = parameterValueText(p, S());
  info.unit = p.unit;
  info.description = p.description;
  info.advanced = p.advanced();
  std::visit(
      [&](const auto& field) {
        if constexpr (std::is_same_v<std::decay_t<decltype(field)>, ChoiceField<S>>) {
          info.type = "string";
          info.range = field.choices;
        } else {
          using T = std::remove_reference_t<decltype(field(std::declval<S&>()))>;
          info.type = detail::typeName(detail::Tag<T>());
          const bool numeric = !std::is_same_v<T, bool> && !std::is_same_v<T, std::string>;
          info.range = numeric ? p.range.text() : "";
        }
      },
      p.field);
  return info;
}

template <class S>
std::vector<ParameterInfo> describeParameters(const std::vector<Parameter<S>>& registry) {
  std::vector<ParameterInfo> out;
  for (const Parameter<S>& p : registry) out.push_back(describeParameter(p));
  return out;
}

/// What is wrong with a shipped file against the registry: a user-facing key missing or not at its default,
/// an advanced key present (the shipped files hold only what a typical user tunes), a key not in the registry.
template <class S>
std::vector<std::string> checkShippedParameters(const std::vector<Parameter<S>>& registry, const YamlParameterSource& file) {
  std::vector<std::string> problems;
  const std::vector<std::string> keys = file.keys();
  auto present = [&](const std::string& k) { return std::find(keys.begin(), keys.end(), k) != keys.end(); };
  const S defaults;
  for (const Parameter<S>& p : registry) {
    if (p.advanced()) {
      if (present(p.name)) problems.push_back(std::string(p.name) + ": advanced, not meant for the shipped file");
      continue;
    }
    if (!present(p.name)) {
      problems.push_back(std::string(p.name) + ": missing");
      continue;
    }
    S read = defaults;
    readParameter(file, p, read);
    const std::string got = parameterValueText(p, read), want = parameterValueText(p, defaults);
    if (got != want) problems.push_back(std::string(p.name) + ": " + got + " but the default is " + want);
  }
  for (const std::string& k : keys) {
    bool known = false;
    for (const Parameter<S>& p : registry) known = known || k == p.name;
    if (!known) problems.push_back(k + ": not a parameter of this node");
  }
  return problems;
}

}  // namespace laser_dpslam
