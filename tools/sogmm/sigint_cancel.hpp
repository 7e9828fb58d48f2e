// Ctrl-C cancels a running fit cleanly (no partial output) instead of killing
// the process mid-write.
#pragma once

#include <csignal>

namespace sogmm::tools {

/// While alive, SIGINT only sets a flag that progress sinks read
/// (requested()); the fit then stops with Error(Cancelled). A second SIGINT
/// gets the default action (ends the process at once), so a stuck command
/// can still be killed. The previous handler is restored on destruction.
class SigintCancel {
 public:
  SigintCancel();
  ~SigintCancel();
  SigintCancel(const SigintCancel&) = delete;
  SigintCancel& operator=(const SigintCancel&) = delete;
  /// True once SIGINT arrived while a SigintCancel was alive.
  static bool requested();

 private:
  struct sigaction previous_ {};
};

}  // namespace sogmm::tools
