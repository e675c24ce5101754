#pragma once
// Xorg with the dummy video driver, started by the windowed tests' fixtures: an X display whose
// monitors xrandr makes and moves, so GLFW windows can be placed, read back and unplugged on a
// machine with no display. Needs root, /usr/bin/Xorg and the dummy driver
// (xserver-xorg-video-dummy); start() says why when it cannot run, for GTEST_SKIP.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

namespace facet::test {

class XorgDummyServer {
 public:
  // Starts Xorg on `display` (":N") with one screen of `virtual_width`×`virtual_height` pixels and
  // `video_ram_kb` of video memory, its config and log in `folder` (which must exist), and waits
  // up to 10 s for it to answer xrandr. Returns "" when it does, else the reason it cannot run.
  std::string start(const std::filesystem::path& folder, const std::string& display,
                    int virtual_width, int virtual_height, int video_ram_kb) {
    if (!std::filesystem::exists("/usr/bin/Xorg") ||
        !std::filesystem::exists("/usr/lib/xorg/modules/drivers/dummy_drv.so")) {
      return "Xorg or its dummy video driver (xserver-xorg-video-dummy) is not installed";
    }
    if (::geteuid() != 0) return "Xorg with the dummy driver needs root here";
    display_ = display;
    const std::filesystem::path config = folder / "xorg.conf", log = folder / "xorg.log";
    std::ofstream(config) << "Section \"Device\"\n  Identifier \"dummy\"\n  Driver \"dummy\"\n"
                          << "  VideoRam " << video_ram_kb << "\nEndSection\n"
                          << "Section \"Monitor\"\n  Identifier \"monitor\"\n"
                          << "  HorizSync 5.0-1000.0\n  VertRefresh 5.0-200.0\nEndSection\n"
                          << "Section \"Screen\"\n  Identifier \"screen\"\n  Device \"dummy\"\n"
                          << "  Monitor \"monitor\"\n  DefaultDepth 24\n  SubSection \"Display\"\n"
                          << "    Depth 24\n    Virtual " << virtual_width << " " << virtual_height
                          << "\n  EndSubSection\nEndSection\n";
    pid_ = ::fork();
    if (pid_ == 0) {
      ::execl("/usr/bin/Xorg", "Xorg", display_.c_str(), "-config", config.c_str(), "-noreset",
              "-nolisten", "tcp", "-logfile", log.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    for (int attempt = 0; attempt < 100 && xrandr("--listmonitors") != 0; ++attempt) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      if (::waitpid(pid_, nullptr, WNOHANG) == pid_) {
        pid_ = -1;
        return "Xorg exited at start; see " + log.string();
      }
    }
    if (xrandr("--listmonitors") != 0) return "Xorg did not answer within 10 s";
    return {};
  }

  void stop() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
  }

  // Runs xrandr on this display with `arguments`, quietly; its exit status.
  int xrandr(const std::string& arguments) const {
    const int status =
        std::system(("DISPLAY=" + display_ + " xrandr " + arguments + " > /dev/null 2>&1").c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  const std::string& display() const { return display_; }

 private:
  std::string display_;
  pid_t pid_ = -1;
};

}  // namespace facet::test
