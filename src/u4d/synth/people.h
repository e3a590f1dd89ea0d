// The people of a synthetic scene: who they are (appearance, body) and what
// they do (a motion timeline), and posing them into SceneFrame::people,
// ::joints and ::coco_keypoints.
//
// Presets (all deterministic in the seed; people stay within ~2.5 m of the
// origin on the floor y = 0, so a camera ring of radius 4-5 m sees them):
//  - MakeHandshakeScript: two people walk towards each other along a random
//    axis through the origin, stop where their right hands meet, shake hands
//    (~1.2 s of pumping), release, turn away and walk apart. While they stand
//    face to face, cameras near the axis see one partly hidden by the other.
//  - MakeMeetupScript: num_people (>= 3) walk in from different directions to
//    a circle of radius ~0.8 m around the origin; persons 0 and 1 shake hands,
//    the others turn to the group; the last person is driven by the real CMU
//    clip (walk + stop, retargeted to that person and placed so the walk ends
//    at its slot).
#pragma once

#include <cstdint>
#include <vector>

#include "u4d/synth/body_mesh.h"
#include "u4d/synth/motion.h"
#include "u4d/synth/scene.h"
#include "u4d/synth/skeleton.h"
#include "u4d/util/file.h"

namespace u4d::synth {

struct PersonScript {
  Appearance appearance;
  BodyShape shape;        // from appearance.height / width
  BodyMeshTemplate mesh;  // built from shape and appearance
  PersonMotion motion;
};

// A planned handshake, for tests and documentation.
struct HandshakeEvent {
  int person_a = 0, person_b = 1;
  double shake_start = 0, shake_end = 0;  // seconds: hands clasped and pumping
};

struct PeopleScript {
  double fps = 25;
  int num_frames = 0;
  std::vector<PersonScript> people;  // instance ids 1..N in this order
  std::vector<MocapClip> clips;      // used by kMocap phases
  std::vector<HandshakeEvent> handshakes;
};

// A person with appearance drawn from `seed`, standing at the origin.
PersonScript MakePerson(uint64_t seed, const BodyMeshOptions& mesh_options = {});

// Two people, a handshake. Needs num_frames / fps >= 4 s (8-10 s shows the
// whole story: approach ~2 s, handshake ~2.6 s, turn and walk apart).
PeopleScript MakeHandshakeScript(int num_frames, double fps, uint64_t seed);

// num_people >= 3 (at most 8) meet; see the file comment. `mocap_bvh` is a
// CMU BVH walk (e.g. the shipped data/mocap/scaled_131_02.bvh). Needs
// num_frames / fps >= 5 s.
PeopleScript MakeMeetupScript(int num_people, int num_frames, double fps, uint64_t seed,
                              const fs::path& mocap_bvh);

// Checks the script's consistency (motions, clip indices, sizes).
void CheckPeopleScript(const PeopleScript& script);

// Time of `frame` in seconds.
inline double FrameTime(const PeopleScript& script, int frame) { return frame / script.fps; }

// The body pose of person `person` at `frame`.
BodyPose PosePerson(const PeopleScript& script, int person, int frame);

// Fills out->time, out->people (instance ids 1..N, label "person", posed
// meshes, materials), out->joints and out->coco_keypoints for `frame`
// (0 <= frame < num_frames). Leaves out->statics alone.
void PosePeople(const PeopleScript& script, int frame, SceneFrame* out);

}  // namespace u4d::synth
