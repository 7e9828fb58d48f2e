// The prepared registration target a model handle keeps between calls
// (sogmm_register_points_f32 / sogmm_register_model): a robot localising
// frames one after another in a fixed map pays the target's preparation
// (validation, each level's smoothed components, boxes and index; about a
// fifth of a d = 5 frame's CPU against 3,000 components) once, not per call.
// The answers are bit-identical either way (sogmm::RegistrationTarget).
//
// A handle's components never change once it is returned (every call that
// makes a model fills a new handle), so the cache is only replaced when a
// call asks for other level options. A copied handle starts with an empty
// cache: the copy's components may still be changed before it is returned.
#pragma once

#include <memory>
#include <mutex>

#include "sogmm/registration.hpp"

namespace sogmm_capi {

class RegistrationCache {
 public:
  RegistrationCache() = default;
  RegistrationCache(const RegistrationCache&) {}
  RegistrationCache& operator=(const RegistrationCache&) {
    const std::lock_guard<std::mutex> lock(mutex_);
    target_.reset();
    return *this;
  }

  /// The target prepared from `gmm` for `options` (prepared on `threads`
  /// when it is not kept yet). Shared: a concurrent call that prepares for
  /// other options does not free the one this caller uses. Errors: those of
  /// sogmm::RegistrationTarget's constructor.
  std::shared_ptr<const sogmm::RegistrationTarget> get(const sogmm::Gmm& gmm,
                                                       const sogmm::RegistrationOptions& options,
                                                       int threads) const {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (!target_ || !target_->prepared_for(options))
      target_ = std::make_shared<const sogmm::RegistrationTarget>(gmm, options, threads);
    return target_;
  }

 private:
  mutable std::mutex mutex_;
  mutable std::shared_ptr<const sogmm::RegistrationTarget> target_;
};

}  // namespace sogmm_capi
