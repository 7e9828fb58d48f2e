#include "sigint_cancel.hpp"

namespace sogmm::tools {
namespace {
volatile std::sig_atomic_t g_requested = 0;

extern "C" void on_sigint(int) { g_requested = 1; }
}  // namespace

SigintCancel::SigintCancel() {
  struct sigaction action {};
  action.sa_handler = on_sigint;
  action.sa_flags = SA_RESETHAND;  // the next Ctrl-C gets the default action
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &previous_);
}

SigintCancel::~SigintCancel() { sigaction(SIGINT, &previous_, nullptr); }

bool SigintCancel::requested() { return g_requested != 0; }

}  // namespace sogmm::tools
