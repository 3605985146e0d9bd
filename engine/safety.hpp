// engine/safety.hpp — non-finite checks between the stages, and the error they raise.
#pragma once

#include "engine/workspace.hpp"
#include "magnetics/moments.hpp"

#include <stdexcept>
#include <string>

namespace magsim::engine {

/// A step produced a non-finite value. The Simulation has been rolled back to the last
/// good state when this is thrown. what() reads e.g.
///   "step 1234: body 17 'ball_17': velocity is not finite (nan)".
class SimulationError : public std::runtime_error {
 public:
  SimulationError(long step, int body, std::string body_name, std::string quantity,
                  const std::string& message)
      : std::runtime_error(message),
        step_(step),
        body_(body),
        body_name_(std::move(body_name)),
        quantity_(std::move(quantity)) {}
  long step() const { return step_; }             ///< the failing step (1-based)
  int body() const { return body_; }  ///< body index, −1 when ODE failed without naming one
  const std::string& body_name() const { return body_name_; }
  const std::string& quantity() const { return quantity_; }  ///< e.g. "velocity"

 private:
  long step_;
  int body_;
  std::string body_name_, quantity_;
};

/// Throws SimulationError for the first non-finite M, M1 or M2 (in moment order).
void check_magnetization(const Model& model, const mag::Magnetization& mz, long step);
/// Throws SimulationError for the first non-finite magnetic force or torque.
void check_forces(const Model& model, const Workspace& ws, long step);
/// Throws SimulationError for the first non-finite position, orientation, velocity or
/// angular velocity of a dynamic or kinematic body, or (quantity "speed") a dynamic body
/// faster than options.max_body_speed.
void check_bodies(const Model& model, const State& s, long step);

}  // namespace magsim::engine
