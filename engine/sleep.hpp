// engine/sleep.hpp — sleeping islands (SimOptions::sleep; the rules in sleep.cpp).
#pragma once

#include "engine/model.hpp"
#include "engine/state.hpp"
#include "magnetics/moments.hpp"

#include <utility>
#include <vector>

namespace magsim::engine {

class OdeBridge;

/// Sizes the State's sleep arrays (still_time, sleep_island, H_sleep) when the model sleeps.
void prepare_sleep(const Model& m, State* s);
/// Bodies asleep in s.
int asleep_count(const State& s);
/// Every dynamic body asleep, the magnetization converged, and no kinematic body moving: a
/// step would change nothing but the clock.
bool world_asleep(const Model& m, const State& s);
/// set->frozen = the moments of the bodies asleep in s (the relaxation leaves them as they are).
void freeze_sleeping(const Model& m, const State& s, mag::MomentDesc* set);
/// After a sub-step's collisions (pairs): wakes each sleeping island that an awake dynamic
/// body or a moving kinematic body touches, in *next and in ODE, and gives its bodies this
/// sub-step's magnetic forces F (and torques tau of permanent moments) at the moments' world
/// positions. Returns the islands woken.
int wake_touched(const Model& m, const std::vector<std::pair<int, int>>& pairs,
                 const mag::MomentDesc& set, const std::vector<Vec3>& F,
                 const std::vector<Vec3>& tau, State* next, OdeBridge* ode);
/// ODE's collisions skip pairs of sleeping and non-dynamic bodies: carries those of `before`
/// (the last state's pairs) with at least one sleeping body into next->contact_pairs, sorted.
void carry_sleeping_pairs(const Model& m, const std::vector<std::pair<int, int>>& before, State* next);
/// At a step's end state, before its audit: the awake bodies' still time, and the islands
/// that fall asleep now (v = ω = 0, enabled 0), listed in *fell_asleep. Their sleep_island
/// is set by finish_sleep, after the end state's solve (they are solved free).
void settle(const Model& m, State* next, std::vector<int>* fell_asleep);
/// After the end state's solve, with the field H at every moment: the islands asleep before
/// the step whose field moved beyond the tolerance wake (their moments are solved free from
/// the next step's end on; its first forces are those of this solve, so E's books run on
/// unbroken); the bodies that fell asleep get their island and H_sleep.
/// Returns the islands woken.
int finish_sleep(const Model& m, const std::vector<int>& fell_asleep, const std::vector<Vec3>& H,
                 State* next);
/// Wakes every body (the user moved or edited one).
void wake_all(const Model& m, State* s);

}  // namespace magsim::engine
