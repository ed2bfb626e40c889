#include "drivers/interrupt.hpp"

#include <csignal>
#include <initializer_list>

namespace fdem {

namespace {

volatile std::sig_atomic_t received_signal = 0;

void record_signal(int signal) {
  received_signal = signal;
}

}  // namespace

void install_interrupt_handlers() {
  struct sigaction action {};
  action.sa_handler = record_signal;
  sigemptyset(&action.sa_mask);
  // SA_RESETHAND: the second SIGTERM (or Ctrl-C) gets the default action and ends the process.
  // SA_RESTART: a signal does not fail the system calls of file output with EINTR.
  action.sa_flags = SA_RESETHAND | SA_RESTART;
  for (int signal : {SIGTERM, SIGINT, SIGUSR1}) sigaction(signal, &action, nullptr);
}

int interrupt_signal() {
  return received_signal;
}

const char* signal_name(int signal) {
  switch (signal) {
    case SIGTERM:
      return "SIGTERM";
    case SIGINT:
      return "SIGINT";
    case SIGUSR1:
      return "SIGUSR1";
    default:
      return "a signal";
  }
}

}  // namespace fdem
