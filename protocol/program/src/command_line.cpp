#include "covtrack/program/command_line.hpp"

#include <functional>
#include <iostream>
#include <sstream>
#include <vector>

#include "covtrack/version.hpp"

namespace covtrack::program {
namespace {

// 1000000 and 0.9999 as people write them (CLI11's own Range prints DBL_MAX with all 309 digits).
std::string number_text(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

// The number `text`, or nothing: the option's own conversion reports what is not a number.
std::optional<double> number(const std::string& text) {
  double v = 0;
  if (!CLI::detail::lexical_cast(text, v)) return std::nullopt;
  return v;
}

CLI::Validator number_check(std::string type, std::function<bool(double)> ok, std::string requirement) {
  return CLI::Validator(
      [ok = std::move(ok), requirement = std::move(requirement)](std::string& text) -> std::string {
        const auto v = number(text);
        if (!v || ok(*v)) return {};
        return requirement + ", got " + text;
      },
      std::move(type));
}

// "covtrack echo": the program and the subcommand the error is about.
std::string command_name(const CLI::App& app) {
  std::string name = app.get_name();
  for (const CLI::App* sub = &app; !sub->get_subcommands().empty();) {
    sub = sub->get_subcommands().front();
    name += " " + sub->get_name();
  }
  return name;
}

// Every subcommand, whether used or not.
std::vector<CLI::App*> all_subcommands(CLI::App& app) {
  return app.get_subcommands(std::function<bool(CLI::App*)>([](CLI::App*) { return true; }));
}

std::string one_line(std::string text) {
  for (char& c : text)
    if (c == '\n') c = ' ';
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

}  // namespace

void add_conventions(CLI::App& app, const std::string& footer) {
  app.set_version_flag("--version", app.get_name() + " " + COVTRACK_VERSION, "Print the version and exit");
  const std::string text = footer.empty() ? kExitCodesHelp : footer + "\n" + kExitCodesHelp;
  app.footer(text);
  for (CLI::App* sub : all_subcommands(app)) sub->footer(kExitCodesHelp);
}

std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
    return std::nullopt;
  } catch (const CLI::RuntimeError& e) {  // a subcommand's own failure, already reported
    return e.get_exit_code();
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);  // --help, --version
    const std::string name = command_name(app);
    std::string what = one_line(e.what());
    if (app.get_subcommands().empty() && !all_subcommands(app).empty()) {
      // CLI11 says "A subcommand is required" for any of these; its first word is what was wrong.
      what = argc < 2 ? "a command is required"
                      : std::string(argv[1][0] == '-' ? "unknown option '" : "unknown command '") + argv[1] + "'";
    }
    std::cerr << name << ": " << what << " (try " << name << " --help)\n";
    return kExitUsageError;
  }
}

CLI::Validator non_negative() {
  return number_check("NONNEGATIVE", [](double v) { return v >= 0; }, "must be 0 or more");
}

CLI::Validator positive() {
  return number_check("POSITIVE", [](double v) { return v > 0; }, "must be more than 0");
}

CLI::Validator in_range(double min, double max) {
  const std::string lo = number_text(min), hi = number_text(max);
  return number_check("[" + lo + " - " + hi + "]", [min, max](double v) { return v >= min && v <= max; },
                      "must be between " + lo + " and " + hi);
}

}  // namespace covtrack::program
