/** @file StopSignal.cpp
 *  @brief SIGINT/SIGTERM handlers that set a flag.
 */
#include "StopSignal.h"

#include <signal.h>
#include <sys/wait.h>

#include <cstring>
#include <ctime>

#include "uwb/io/FileAccess.h"

namespace uwb::app {
namespace {

volatile std::sig_atomic_t g_stop = 0;

extern "C" void onStopSignal(int) { g_stop = 1; }

}  // namespace

void installStopHandlers() {
  struct sigaction sa;
  std::memset(&sa, 0, sizeof sa);
  sa.sa_handler = onStopSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: a blocking read() returns EINTR
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  std::signal(SIGPIPE, SIG_IGN);
  sigset_t set;  // a parent may have blocked them (the mask survives exec)
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigprocmask(SIG_UNBLOCK, &set, nullptr);
}

namespace {

volatile std::sig_atomic_t g_child = 0;

/// Stops the child and waits for it (up to 2 s, then SIGKILL), so that it cannot create a file after the temporary
/// files are removed. Only async-signal-safe calls.
void stopChild(pid_t child) {
  ::kill(child, SIGTERM);
  const struct timespec step{0, 10'000'000};  // 10 ms
  for (int i = 0; i < 200; ++i) {
    if (::waitpid(child, nullptr, WNOHANG) != 0) return;  // reaped, or not ours to wait for
    ::nanosleep(&step, nullptr);
  }
  ::kill(child, SIGKILL);
  ::waitpid(child, nullptr, 0);
}

extern "C" void onFatalSignal(int sig) {
  if (const pid_t child = static_cast<pid_t>(g_child); child > 0) stopChild(child);
  uwb::removeTemporaryFilesOnSignal();
  std::signal(sig, SIG_DFL);  // async-signal-safe; then die of the same signal (the parent sees it)
  std::raise(sig);
}

}  // namespace

void setChildToStopOnSignal(pid_t pid) { g_child = static_cast<std::sig_atomic_t>(pid); }

void installCleanupHandlers() {
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old;
    if (sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;  // e.g. nohup
    struct sigaction sa;
    std::memset(&sa, 0, sizeof sa);
    sa.sa_handler = onFatalSignal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sigaction(sig, &sa, nullptr);
  }
}

const volatile std::sig_atomic_t* stopFlag() { return &g_stop; }

}  // namespace uwb::app
