#include "relief_snake/option_table.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <sstream>
#include <utility>
#include <variant>

#include "relief_snake/error.hpp"

namespace relief_snake {

namespace {

struct Row {
  OptionInfo info;
  /// Sets the field from a value of the row's type (checked by the caller); false if out of range.
  std::function<bool(Options&, const OptionValue&)> set;
  std::function<OptionValue(const Options&)> get;
};

// The shortest decimal text that reads back as exactly x ("0.2", not "0.20000000000000001").
std::string number_json(double x) {
  for (int digits = 6; digits <= 17; ++digits) {
    std::ostringstream s;
    s.precision(digits);
    s << x;
    if (std::strtod(s.str().c_str(), nullptr) == x) return s.str();
  }
  return std::to_string(x);
}

// How a value is shown in messages.
std::string shown(const OptionValue& value) {
  if (const bool* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
  if (const long long* n = std::get_if<long long>(&value)) return std::to_string(*n);
  if (const double* x = std::get_if<double>(&value)) return number_json(*x);
  return std::get<std::string>(value);
}

[[noreturn]] void bad_value(const OptionInfo& info, const std::string& text) {
  throw Error(std::string("option ") + info.name + " must be " + info.range + ", got '" + text + "'");
}

// Whole-number options are ints; larger values are refused before the cast.
constexpr long long kLargestInteger = 100000000;

Row number(const char* name, double Options::*field, const char* range, bool (*valid)(double), const char* help) {
  return {OptionInfo{name, OptionType::Number, range, help},
          [=](Options& o, const OptionValue& v) {
            const double x = std::get<double>(v);
            if (!std::isfinite(x) || !valid(x)) return false;
            o.*field = x;
            return true;
          },
          [=](const Options& o) { return OptionValue(o.*field); }};
}

Row integer(const char* name, int Options::*field, const char* range, bool (*valid)(long long), const char* help) {
  return {OptionInfo{name, OptionType::Integer, range, help},
          [=](Options& o, const OptionValue& v) {
            const long long n = std::get<long long>(v);
            if (n > kLargestInteger || !valid(n)) return false;
            o.*field = static_cast<int>(n);
            return true;
          },
          [=](const Options& o) { return OptionValue(static_cast<long long>(o.*field)); }};
}

Row boolean(const char* name, bool Options::*field, const char* help) {
  return {OptionInfo{name, OptionType::Boolean, "0, 1, true or false", help},
          [=](Options& o, const OptionValue& v) {
            o.*field = std::get<bool>(v);
            return true;
          },
          [=](const Options& o) { return OptionValue(o.*field); }};
}

// A choice between named values of an enum.
template <class Enum>
Row choice(const char* name, Enum Options::*field, const char* range,
           std::vector<std::pair<const char*, Enum>> names, const char* help) {
  return {OptionInfo{name, OptionType::Choice, range, help},
          [=](Options& o, const OptionValue& v) {
            const std::string& text = std::get<std::string>(v);
            for (const auto& [n, e] : names)
              if (text == n) {
                o.*field = e;
                return true;
              }
            return false;
          },
          [=](const Options& o) {
            for (const auto& [n, e] : names)
              if (o.*field == e) return OptionValue(std::string(n));
            return OptionValue(std::string("?"));
          }};
}

Row neighbourhood(const char* name, Neighbourhood Options::*field, const char* help) {
  return choice(name, field, "geodesic, euclidean or sphere",
                {{"geodesic", Neighbourhood::Geodesic}, {"euclidean", Neighbourhood::Euclidean},
                 {"sphere", Neighbourhood::Sphere}},
                help);
}

Row plane_fit(const char* name, PlaneFit Options::*field, const char* help) {
  return choice(name, field, "vertices, vertex_areas or area",
                {{"vertices", PlaneFit::Vertices}, {"vertex_areas", PlaneFit::VertexAreas}, {"area", PlaneFit::Area}},
                help);
}

// The text form (the CLI's --option NAME=VALUE) as a value of the row's type.
OptionValue parse_text(const OptionInfo& info, const std::string& text) {
  switch (info.type) {
    case OptionType::Number: {
      errno = 0;
      char* end = nullptr;
      const double x = std::strtod(text.c_str(), &end);
      if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(x))
        bad_value(info, text);
      return x;
    }
    case OptionType::Integer: {
      errno = 0;
      char* end = nullptr;
      const long long n = std::strtoll(text.c_str(), &end, 10);
      if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE) bad_value(info, text);
      return n;
    }
    case OptionType::Boolean:
      if (text == "1" || text == "true") return true;
      if (text == "0" || text == "false") return false;
      bad_value(info, text);
    case OptionType::Choice:
      return text;
  }
  bad_value(info, text);
}

const std::vector<Row>& rows() {
  static const std::vector<Row> table = {
      number("tau", &Options::tau, "in (0, 1)", [](double x) { return x > 0 && x < 1; },
             "movement step, fraction of the local segment length (paper: 0.2)"),
      number("epsilon", &Options::epsilon, "in [0, 1)", [](double x) { return x >= 0 && x < 1; },
             "q_i is searched over (1 +- epsilon) h (paper: 0.2)"),
      integer("q_samples", &Options::q_samples, "a whole number from 1 to 64", [](long long n) { return n >= 1 && n <= 64; },
              "candidate q_i positions across that range"),
      boolean("exact_q", &Options::exact_q,
              "search q_i over the whole (1 +- epsilon) h stretch instead of q_samples points (not in the paper)"),
      number("max_turn_degrees", &Options::max_turn_degrees, "in (0, 180]", [](double x) { return x > 0 && x <= 180; },
             "snaxels turning more than this are removed (paper: 160)"),
      integer("lock_interval", &Options::lock_interval, "a whole number >= 1", [](long long n) { return n >= 1; },
              "oscillation lock check every this many iterations (paper: 10)"),
      number("feature_contrast", &Options::feature_contrast, "> 0", [](double x) { return x > 0; },
             "planarity contrast, in units of h, that scores E_f = -1 at l = h (normalisation of gamma)"),
      boolean("scale_feature_with_spacing", &Options::scale_feature_with_spacing,
              "gamma scales with 1/l between phases, like alpha"),
      boolean("convex_barrier", &Options::convex_barrier,
              "also penalise P^(v) < P^(q) (experimental, not in the paper)"),
      boolean("remove_loops", &Options::remove_loops, "cut off loops where the snake crosses itself (not in the paper)"),
      boolean("refit_step_height", &Options::refit_step_height,
              "segment again with the step measured along the contour when it disagrees with h (not in the paper)"),
      number("refit_ratio", &Options::refit_ratio, "> 1", [](double x) { return x > 1; },
             "refit h when the step found and h differ by more than this factor"),
      number("refit_ratio_up", &Options::refit_ratio_up, "> 1", [](double x) { return x > 1; },
             "refit h already when the step found exceeds h by this factor (at most refit_ratio)"),
      choice("retry_estimate", &Options::retry_estimate, "off, no_result, doubtful_flagged or doubtful",
             {{"off", EstimateRetry::Off}, {"no_result", EstimateRetry::NoResult},
              {"doubtful_flagged", EstimateRetry::DoubtfulFlagged}, {"doubtful", EstimateRetry::Doubtful}},
             "with h estimated: segment again at the estimator's further guesses of h when the first estimate "
             "gives no result (no_result), or also a doubtful one (doubtful_flagged: what comes of it stays "
             "doubtful; doubtful: its own verdict stands), keeping the best evidence (not in the paper)"),
      boolean("foot_snap", &Options::foot_snap,
              "after stabilisation, move the contour out to the foot of the step, where the surface leaves "
              "the background (not in the paper)"),
      boolean("wall_foot", &Options::wall_foot,
              "move snaxels resting on a sharp step's tall wall down to its foot (not in the paper)"),
      boolean("coarse_relief_kept", &Options::coarse_relief_kept,
              "self-check: a refined region far from the coarse contour's is doubtful only if it lost the "
              "coarse region's relief, not background the coarse contour bridged (not in the paper)"),
      boolean("confirmed_step", &Options::confirmed_step,
              "with the refit: a contour whose step (x1.5 to x2 off h) the refit measured again at that height, "
              "with weaker evidence there, is judged against x2 rather than the refit's x1.5 (not in the paper)"),
      boolean("edge_step_refit", &Options::edge_step_refit,
              "with the refit: a result that fails the self-check is segmented once more with h = the step "
              "measured at its edge, where that disagrees with h (not in the paper)"),
      number("far_run_checked", &Options::far_run_checked, "in [0, 100]", [](double x) { return x >= 0 && x <= 100; },
             "the self-check fails a contour with a stretch longer than this many h away from the step (over 5% "
             "of it, h at least 3 average edges) even where the region-wide check found no background inside "
             "(0: off) (not in the paper)"),
      boolean("foot_snap_blended", &Options::foot_snap_blended,
              "the foot stage only where the contour sits on a blended step over a clean background (half the "
              "step at least 1.5 edges inside it, the outside quadrics' residual under foot_gate_residual of h) (not in the paper)"),
      number("foot_pool", &Options::foot_pool, "in [0, 5]", [](double x) { return x >= 0 && x <= 5; },
             "the blended foot stage: pool each snaxel's profile outwards with its neighbours' over this "
             "length of contour on each side, in h, before finding the foot (0: each alone) (not in the paper)"),
      number("foot_gate_residual", &Options::foot_gate_residual, "in (0, 1]", [](double x) { return x > 0 && x <= 1; },
             "the blended foot stage runs where the outside quadrics' residual is under this share of h "
             "(not in the paper)"),
      number("foot_gate_clearance", &Options::foot_gate_clearance, "in [0, 2]", [](double x) { return x >= 0 && x <= 2; },
             "the blended foot stage's gate measures the outside quadrics' residual on the vertices at least "
             "this many h from the region (0: all outside vertices) (not in the paper)"),
      boolean("foot_toe", &Options::foot_toe,
              "the blended foot stage: fit the step's quadratic toe inwards of where it clears the background "
              "and put the foot where the toe meets it (not in the paper)"),
      number("region_check_smoothing", &Options::region_check_smoothing, "in [0, 5]",
             [](double x) { return x >= 0 && x <= 5; },
             "the region-wide check's background fills: fit the ring's inner band softly over this length, in "
             "h (0: the ring is fixed exactly) (not in the paper)"),
      number("region_check_band", &Options::region_check_band, "in [0, 3]",
             [](double x) { return x >= 0 && x <= 3; },
             "the region-wide check's background fills: the inner band of their 3 h ring fitted softly, in h "
             "(3: the whole ring) (not in the paper)"),
      number("region_check_textured_smoothing", &Options::region_check_textured_smoothing, "in [0, 5]",
             [](double x) { return x >= 0 && x <= 5; },
             "the region-wide check: where the ring's quadric sees a deep piece the fills do not, fill again "
             "softly over the whole ring with this smoothing length, in h (0: no second opinion) (not in the paper)"),
      number("region_check_textured_roughness", &Options::region_check_textured_roughness, "in [0, 1]",
             [](double x) { return x >= 0 && x <= 1; },
             "the region-wide check's second opinion: only where the background's roughness outside the "
             "contour is at least this share of the step (a textured ring) (not in the paper)"),
      boolean("height_outline", &Options::height_outline,
              "closed contours: when no refinement passes the self-check, refine once more from just outside "
              "what stands half a step above the background filled in under the region (not in the paper)"),
      boolean("repair_background", &Options::repair_background,
              "closed contours: cut out a piece of background the region took in (a bridged concavity, a lobe) "
              "and refine again from the rest (not in the paper)"),
      integer("refine_levels", &Options::refine_levels, "a whole number from 0 to 16",
              [](long long n) { return n >= 0 && n <= 16; },
              "refinement spacings: 1 = the paper (straight to half an edge); 0 = coarse to fine from h/2 in "
              "ratios of at most 2; n = the same in at most n levels (not in the paper)"),
      boolean("nearest_resampling", &Options::nearest_resampling,
              "new snaxels at the surface point nearest the chord, not at the end of a surface walk along it"),
      neighbourhood("neighbourhood", &Options::neighbourhood,
                    "planarity neighbourhood: geodesic h-ball (paper), straight-distance h-ball connected to v, "
                    "or every part of the surface within straight distance h facing v's side (a moment tree)"),
      plane_fit("plane_fit", &Options::plane_fit,
                "planarity plane fitted to the neighbourhood's vertices (paper), to its vertices weighted by "
                "their areas, or to its surface area"),
      boolean("planarity_one_ring", &Options::planarity_one_ring,
              "the one-ring always counts as planarity neighbours (not in the paper)"),
      integer("threads", &Options::threads, "a whole number >= 0 (0: all cores)",
              [](long long n) { return n >= 0 && n <= 4096; }, "threads for the planarity batches; results do not depend on it"),
  };
  return table;
}

const Row* find(const std::string& name) {
  for (const Row& r : rows())
    if (name == r.info.name) return &r;
  return nullptr;
}

}  // namespace

const std::vector<OptionInfo>& advanced_options() {
  static const std::vector<OptionInfo> infos = [] {
    std::vector<OptionInfo> out;
    for (const Row& r : rows()) out.push_back(r.info);
    return out;
  }();
  return infos;
}

std::string advanced_option_names() {
  std::string names;
  for (const Row& r : rows()) names += (names.empty() ? "" : ", ") + std::string(r.info.name);
  return names;
}

namespace {

const Row& row_of(const std::string& name) {
  const Row* row = find(name);
  if (!row) throw Error("unknown option '" + name + "'; valid names: " + advanced_option_names());
  return *row;
}

}  // namespace

void set_advanced_option(Options* options, const std::string& name, const std::string& value) {
  const Row& row = row_of(name);
  if (!row.set(*options, parse_text(row.info, value))) bad_value(row.info, value);
}

void set_advanced_option_value(Options* options, const std::string& name, const OptionValue& value) {
  const Row& row = row_of(name);
  OptionValue typed = value;
  // A whole number is a number too.
  if (row.info.type == OptionType::Number && std::holds_alternative<long long>(value))
    typed = static_cast<double>(std::get<long long>(value));
  const bool right_type =
      (row.info.type == OptionType::Number && std::holds_alternative<double>(typed)) ||
      (row.info.type == OptionType::Integer && std::holds_alternative<long long>(typed)) ||
      (row.info.type == OptionType::Boolean && std::holds_alternative<bool>(typed)) ||
      (row.info.type == OptionType::Choice && std::holds_alternative<std::string>(typed));
  if (!right_type || !row.set(*options, typed)) bad_value(row.info, shown(value));
}

OptionValue advanced_option_value(const Options& options, const std::string& name) {
  return row_of(name).get(options);
}

std::string advanced_option_json(const Options& options, const std::string& name) {
  const OptionValue value = advanced_option_value(options, name);
  if (const bool* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
  if (const long long* n = std::get_if<long long>(&value)) return std::to_string(*n);
  if (const double* x = std::get_if<double>(&value)) return number_json(*x);
  return "\"" + std::get<std::string>(value) + "\"";
}

}  // namespace relief_snake
