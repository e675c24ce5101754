// facet devices: USB cameras and projector controllers, and their stable identities.
#include <atomic>
#include <chrono>
#include <csignal>
#include <iostream>

#include "command.hpp"
#include "facet/interop/usb_devices.hpp"
#include "facet/projection/errors.hpp"

namespace facet::cli {
namespace {

std::atomic<bool> interrupted{false};

const Registration registration{
    70, [](CLI::App& app) {
      auto* command = app.add_subcommand(
          "devices",
          "List USB devices (VID:PID, role, serial, bus path, stable id); --watch follows hotplug");
      struct Options {
        bool watch = false;
        double seconds = 0;
        std::string find;
      };
      auto options = std::make_shared<Options>();
      command->add_flag("--watch", options->watch, "Keep running and report arrivals and removals");
      command->add_option("--for", options->seconds,
                          "With --watch: stop after this many seconds (default: until Ctrl-C)");
      command->add_option("--find", options->find,
                          "Only the devices a stable id (usb:VVVV:PPPP[:SERIAL|@BUS-PATH]) names");
      command->callback([options, command] {
        // Left out, --watch goes on until Ctrl-C; given, it is a time in (0, 1e6] s (11.6 days):
        // 0, NaN, infinity or 1e308 would watch forever.
        if (command->count("--for") > 0) {
          if (!options->watch) throw InputError("--for", "", "--watch as well: it times the watch");
          if (!(options->seconds > 0 && options->seconds <= 1e6)) {
            throw InputError("--for", "", "seconds in (0, 1e6]; leave --for out to stop on Ctrl-C");
          }
        }
        const interop::UsbListing listing = interop::list_usb_devices();
        if (!listing.problem.empty()) std::cerr << "facet: note: " << listing.problem << "\n";
        std::vector<interop::UsbDevice> devices = listing.devices;
        if (!options->find.empty()) {
          if (const std::string problem = interop::stable_id_problem(options->find);
              !problem.empty()) {
            throw InputError("--find", "", problem);
          }
          devices = interop::find_devices(options->find, devices);
        }
        std::cout << interop::format_devices(devices) << std::flush;
        if (!options->watch) return;
        std::signal(SIGINT, [](int) { interrupted = true; });
        const auto start = std::chrono::steady_clock::now();
        const double limit = options->seconds;
        std::cout << "watching for arrivals and removals ("
                  << interop::to_string(interop::usb_watch_method()) << "); Ctrl-C stops"
                  << std::endl;
        interop::watch_usb_devices(
            [](const interop::UsbChange& change) {
              std::cout << interop::format_change(change) << std::endl;
            },
            [start, limit] {
              const double elapsed =
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
              return !interrupted && (limit <= 0 || elapsed < limit);
            });
      });
    }};

}  // namespace
}  // namespace facet::cli
