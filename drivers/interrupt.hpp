// Interruption by a signal: batch systems send SIGTERM (or SIGUSR1 with e.g. Slurm's --signal)
// some time before they kill a job at the end of its time; Ctrl-C sends SIGINT.  The handler only
// records the signal (async-signal-safe); the run loop looks at it once per step, every rank
// learns it through the step's existing reduction, and the run ends after that step with a
// checkpoint and summary.json status "interrupted" (drivers/simulation.cpp).
#pragma once

namespace fdem {

// Installs the handler for SIGTERM, SIGINT and SIGUSR1.  Each is reset to its default action
// when it arrives, so a second identical signal ends the process at once.
void install_interrupt_handlers();

// The signal received so far (0: none).
int interrupt_signal();

// "SIGTERM", "SIGINT", "SIGUSR1" (or "a signal" for another number).
const char* signal_name(int signal);

}  // namespace fdem
