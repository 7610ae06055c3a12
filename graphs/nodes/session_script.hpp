#pragma once
/// @file
/// @brief The embedded synthetic session `orthoflow run` plays by default: a scripted tabletop
/// where objects of several categories appear, move and leave, and an instructor teaches the first
/// instance of every category but one. It exercises tracking (a long-lived object and a sliding
/// one), teaching (a taught category must be recognised on a new instance) and Unknown (the
/// never-taught category).
#include <cstdint>
#include <string_view>

#include "simulation/world/synthetic_sequence.hpp"

namespace orthoflow::graphs {

/// @brief Frames of the embedded session (10 s at 30 Hz).
inline constexpr std::uint64_t SESSION_FRAMES = 300;

/// @brief The session script for @p frames frames (phases scale with it). Deterministic in @p seed
/// (instance shapes and the sensor noise vary with it, the choreography does not).
/// Phase 1 (first 40%): first instances of mug, bottle and bowl; the mug slides.
/// Phase 2 (from 45%): second instances of mug and bottle and a plate (never taught) appear;
/// the bowl stays for the whole session.
[[nodiscard]] simulation::SequenceScript make_session_script(std::uint64_t frames,
                                                             std::uint64_t seed);

/// @brief True if the scripted instructor teaches this category (all session categories but
/// "plate").
[[nodiscard]] bool instructor_teaches(std::string_view category) noexcept;

}  // namespace orthoflow::graphs
