#pragma once
// Takes and time on the studio's streams (docs/STUDIO.md).
//
// A pose take numbers its motion frames from 0; a cloth take numbers its frames as drape
// run does, from 0, the state before the first step, at the scene's frame rate, with the
// avatar blending from its rest pose into motion frame 0 over the lead-in. So cloth frame k
// shows simulation time k / rate, which is motion time k / rate - leadIn: its time code is
// the pose take's start plus k - leadIn * rate frames, earlier than the take's start while
// the lead-in lasts.

#include <cstdint>
#include <string>

#include "drape/core/timecode.hpp"

namespace drape::studio {

/// A new take's name: the UTC date and time and a random suffix ("20261201T193000Z-3fa2"),
/// which sorts by time and tells two takes of the same second apart.
[[nodiscard]] std::string newTakeId();

/// The Nats-Msg-Id of a message: the stream drops one published twice under the same id
/// (a restarted server sending again what it had sent).
[[nodiscard]] std::string messageId(const std::string& take, const char* kind, std::int64_t frame,
                                    std::int64_t garment = -1);

/// The number of motion frames that must have arrived (frames 0 .. n - 1) before cloth
/// frame `clothFrame` can be simulated: the frames its substeps interpolate between, and
/// the one after them, as a motion that was all there would give them (an interpolation
/// does not clamp at a frame that only has not come yet).
[[nodiscard]] std::int64_t motionFramesNeeded(std::int64_t clothFrame, double clothRate, double leadIn_s,
                                              double motionRate);

/// The cloth frames after frame 0 that a take of `motionFrames` frames is simulated over:
/// the lead-in and the whole motion, as drape run simulates by default.
[[nodiscard]] std::int64_t clothFramesOf(std::int64_t motionFrames, double clothRate, double leadIn_s,
                                         double motionRate);

/// The time code of cloth frame `clothFrame` of a cloth take that follows a pose take
/// starting at `poseStart`.
[[nodiscard]] TimeCode clothTimeCode(std::int64_t clothFrame, const TimeCode& poseStart, double leadIn_s);

}  // namespace drape::studio
