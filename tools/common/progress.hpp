// Progress on a terminal, shared by the tools: one line on stderr per stage, redrawn at most
// every 100 ms, with the fraction done, the time spent and an estimate of the time left.
//
//   bake N_p         [##########          ]  50.0%   4.1 s, about 4 s left
//   writing          hairlut-default.h5                  1.2 s
//
// The estimate is the rate so far (time per unit of work since the count started), shown once a
// tenth of the work or a second has passed, so that the first, unsteady units do not give a wild
// number. A count runs while `total` stays the same and `done` does not go back, whatever the
// stage's name (the validator names each check of one count of six); a new count starts a line. Stages whose work cannot be counted (writing a file) show
// what is being done and the time spent instead, so that a long write is never a silent pause.
// Nothing is drawn when disabled (--quiet, or stderr not a terminal).
#pragma once

#include <chrono>
#include <cstdio>
#include <string>
#include <string_view>

namespace hairlut::tools {

class Progress {
 public:
  explicit Progress(bool enabled) : enabled_(enabled) {}
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  ~Progress() { finish(); }

  /// `done` of `total` units of `stage` are done (the library's progress callbacks).
  void update(std::string_view stage, std::size_t done, std::size_t total) {
    if (!enabled_) return;
    const Clock::time_point now = Clock::now();
    if (!counted_ || !open_ || total != total_ || done < done_) start_stage(stage, now);
    stage_ = std::string(stage);
    total_ = total, done_ = done;
    if (done < total && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    const double frac = total ? static_cast<double>(done) / static_cast<double>(total) : 1.0;
    const double secs = std::chrono::duration<double>(now - stage_start_).count();
    std::string eta;
    if (done > 0 && done < total && (frac >= 0.1 || secs >= 1.0)) eta = ", about " + format_seconds(secs * (1.0 - frac) / frac) + " left";
    constexpr int kWidth = 20;
    const int filled = static_cast<int>(frac * kWidth);
    std::fprintf(stderr, "\r%-16.16s [%s%s] %5.1f%% %6.1f s%-24s", stage_.c_str(), std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(kWidth - filled), ' ').c_str(), 100.0 * frac, secs, eta.c_str());
    open_ = done < total;
    if (done >= total) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }

  /// A stage whose work is not counted, such as writing `what`: shown at once, with the time it
  /// has taken when the next stage or finish() ends it.
  void stage(std::string_view stage, std::string_view what) {
    if (!enabled_) return;
    const Clock::time_point now = Clock::now();
    start_stage(stage, now);
    std::fprintf(stderr, "\r%-16.16s %-40.40s", stage_.c_str(), std::string(what).c_str());
    open_ = true;
    counted_ = false;
    std::fflush(stderr);
  }

  /// Ends the current line (an uncounted stage with its time).
  void finish() {
    if (!enabled_ || !open_) return;
    if (!counted_) std::fprintf(stderr, " %6.1f s", std::chrono::duration<double>(Clock::now() - stage_start_).count());
    end_line();
    std::fflush(stderr);
  }

  /// "12 s", "3 min 05 s", "1 h 02 min".
  static std::string format_seconds(double s) {
    char buf[32];
    if (!(s >= 0.0)) s = 0.0;
    const long total = static_cast<long>(s + 0.5);
    if (total < 60)
      std::snprintf(buf, sizeof buf, "%ld s", total);
    else if (total < 3600)
      std::snprintf(buf, sizeof buf, "%ld min %02ld s", total / 60, total % 60);
    else
      std::snprintf(buf, sizeof buf, "%ld h %02ld min", total / 3600, total / 60 % 60);
    return buf;
  }

 private:
  using Clock = std::chrono::steady_clock;

  void start_stage(std::string_view stage, Clock::time_point now) {
    finish();
    stage_ = std::string(stage);
    stage_start_ = now;
    last_ = {};
    counted_ = true;
    open_ = true;
    done_ = 0;
  }
  void end_line() {
    std::fprintf(stderr, "\n");
    open_ = false;
  }

  bool enabled_;
  bool open_ = false, counted_ = true;
  std::string stage_;
  std::size_t total_ = 0, done_ = 0;
  Clock::time_point stage_start_{}, last_{};
};

}  // namespace hairlut::tools
