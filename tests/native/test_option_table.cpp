// The advanced options by name (option_table.hpp): every front end sets and reports them through it.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "relief_snake/error.hpp"
#include "relief_snake/option_table.hpp"

namespace rs = relief_snake;

TEST(OptionTable, EveryOptionRoundTripsItsDefault) {
  const rs::Options defaults;
  std::set<std::string> names;
  for (const rs::OptionInfo& info : rs::advanced_options()) {
    EXPECT_TRUE(names.insert(info.name).second) << "duplicate " << info.name;
    EXPECT_GT(std::string(info.help).size(), 10u) << info.name;
    // Setting an option to its own printed default changes nothing.
    std::string text = rs::advanced_option_json(defaults, info.name);
    if (text.front() == '"') text = text.substr(1, text.size() - 2);
    rs::Options o;
    rs::set_advanced_option(&o, info.name, text);
    EXPECT_EQ(rs::advanced_option_json(o, info.name), rs::advanced_option_json(defaults, info.name)) << info.name;
  }
  EXPECT_TRUE(names.count("tau") && names.count("neighbourhood") && names.count("plane_fit"));
}

TEST(OptionTable, SetsTheFields) {
  rs::Options o;
  rs::set_advanced_option(&o, "tau", "0.25");
  rs::set_advanced_option(&o, "q_samples", "7");
  rs::set_advanced_option(&o, "exact_q", "true");
  rs::set_advanced_option(&o, "remove_loops", "0");
  rs::set_advanced_option(&o, "neighbourhood", "sphere");
  rs::set_advanced_option(&o, "plane_fit", "area");
  EXPECT_EQ(o.tau, 0.25);
  EXPECT_EQ(o.q_samples, 7);
  EXPECT_TRUE(o.exact_q);
  EXPECT_FALSE(o.remove_loops);
  EXPECT_EQ(o.neighbourhood, rs::Neighbourhood::Sphere);
  EXPECT_EQ(o.plane_fit, rs::PlaneFit::Area);
  EXPECT_EQ(rs::advanced_option_json(o, "tau"), "0.25");
  EXPECT_EQ(rs::advanced_option_json(o, "exact_q"), "true");
  EXPECT_EQ(rs::advanced_option_json(o, "neighbourhood"), "\"sphere\"");
}

TEST(OptionTable, BadValuesAndNamesSayWhatIsAccepted) {
  rs::Options o;
  auto message = [&](const std::string& name, const std::string& value) {
    try {
      rs::set_advanced_option(&o, name, value);
    } catch (const rs::Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("tau", "1.5").find("in (0, 1)"), std::string::npos);
  EXPECT_NE(message("tau", "abc").find("'abc'"), std::string::npos);
  EXPECT_NE(message("q_samples", "2.5").find("whole number"), std::string::npos);
  EXPECT_NE(message("exact_q", "maybe").find("0, 1, true or false"), std::string::npos);
  EXPECT_NE(message("plane_fit", "faces").find("vertices, vertex_areas or area"), std::string::npos);
  EXPECT_NE(message("bogus", "1").find("valid names"), std::string::npos);
  EXPECT_EQ(o.tau, rs::Options().tau);  // a refused value leaves the field alone
}
