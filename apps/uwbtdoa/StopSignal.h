/** @file StopSignal.h
 *  @brief SIGINT/SIGTERM as a stop request for the live commands (`stream`, `replay`): the handler only sets a flag
 *         (installed without SA_RESTART, so a blocking read returns); the command then flushes and exits 0. SIGPIPE
 *         is ignored so a closed consumer shows as a write error instead of killing the process.
 */
#pragma once

#include <sys/types.h>

#include <csignal>

namespace uwb::app {

void installStopHandlers();

/// For every command, at start: SIGINT, SIGTERM and SIGHUP remove the temporary files of outputs being written
/// (uwb::removeTemporaryFilesOnSignal, async-signal-safe), then end the process by the same signal. A signal the
/// parent set to be ignored stays ignored. installStopHandlers() replaces SIGINT and SIGTERM for the live commands.
void installCleanupHandlers();

/// The child process (e.g. the plotting interpreter) that the cleanup handlers stop (SIGTERM) before removing the
/// temporary files, so that it does not write one after them; 0: none.
void setChildToStopOnSignal(pid_t pid);
/// Set (non-zero) once SIGINT or SIGTERM arrived.
const volatile std::sig_atomic_t* stopFlag();

}  // namespace uwb::app
