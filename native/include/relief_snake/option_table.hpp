#pragma once
// The advanced fields of Options by name, so every front end (the CLI's
// --option NAME=VALUE, the Python module's keyword arguments, reports) sets,
// checks and prints them the same way. A new advanced option is one row in
// option_table.cpp.
#include <string>
#include <variant>
#include <vector>

#include "relief_snake/segment.hpp"

namespace relief_snake {

enum class OptionType { Number, Integer, Boolean, Choice };

/// One advanced option: its name, type and the values it accepts (for messages and help).
struct OptionInfo {
  const char* name;
  OptionType type;
  const char* range;  ///< e.g. "in (0, 1)", "0, 1, true or false", "geodesic or euclidean"
  const char* help;   ///< one line: what it does
};

/// Every advanced option, in a fixed order.
const std::vector<OptionInfo>& advanced_options();

/// "tau, epsilon, ...": the names, for messages.
std::string advanced_option_names();

/// An advanced option's value: bool (Boolean), long long (Integer), double (Number) or the
/// choice's name (Choice).
using OptionValue = std::variant<bool, long long, double, std::string>;

/// Sets option `name` from a typed value (the module's keyword arguments): a Number takes a
/// double or a long long, the other types exactly their own alternative. Throws Error like the
/// text form for a value of the wrong type or out of range.
void set_advanced_option_value(Options* options, const std::string& name, const OptionValue& value);

/// The value of option `name`.
OptionValue advanced_option_value(const Options& options, const std::string& name);

/// Sets option `name` from its text form ("0.25", "1", "true", "euclidean").
/// Throws Error with one line naming the option, the accepted values and what was given,
/// or the valid names for an unknown option.
void set_advanced_option(Options* options, const std::string& name, const std::string& value);

/// The value of option `name` as JSON text: a number, true/false or a quoted string.
std::string advanced_option_json(const Options& options, const std::string& name);

}  // namespace relief_snake
