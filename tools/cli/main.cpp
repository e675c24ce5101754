#include <algorithm>
#include <exception>
#include <iostream>
#include <string>

#include "command.hpp"
#include "facet/projection/errors.hpp"
#include "facet/projection/interrupt.hpp"

namespace facet::cli {

std::vector<std::pair<int, CommandSetup>>& CommandRegistry::commands() {
  static std::vector<std::pair<int, CommandSetup>> registered;
  return registered;
}

Registration::Registration(int order, CommandSetup setup) {
  CommandRegistry::commands().emplace_back(order, std::move(setup));
}

}  // namespace facet::cli

int main(int argc, char** argv) {
  CLI::App app{
      "facet: calibration and piecewise perspective rendering for dome, cylinder and "
      "wall projector displays"};
  app.require_subcommand(1);
  auto commands = facet::cli::CommandRegistry::commands();
  std::stable_sort(commands.begin(), commands.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto& [order, setup] : commands) setup(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  } catch (const facet::Interrupted& e) {
    // A long command stopped on SIGINT or SIGTERM after removing its temporary outputs; what()
    // says what was done.
    const std::string command =
        app.get_subcommands().empty() ? "" : " " + app.get_subcommands().front()->get_name();
    std::cerr << "facet" << command << ": interrupted by " << facet::signal_name(e.signal()) << ": "
              << e.what() << "\n";
    return e.exit_status();
  } catch (const facet::InputError& e) {
    std::cerr << "facet: error: " << e.what() << "\n";
    return 2;
  } catch (const facet::PeerLost& e) {
    std::cerr << "facet: stopped: " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    std::cerr << "facet: internal error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
