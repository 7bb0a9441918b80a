/** @file StopSignal.cpp
 *  @brief SIGINT/SIGTERM handlers that set a flag.
 */
#include "StopSignal.h"

#include <cstring>

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

const volatile std::sig_atomic_t* stopFlag() { return &g_stop; }

}  // namespace uwb::app
