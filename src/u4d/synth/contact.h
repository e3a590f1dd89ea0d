// Which people of a synthetic scene are in contact: their surfaces come within
// a distance of each other. Ground truth for "people touch" (a detector tends
// to merge people in contact; docs/synthetic.md), written as gt/contacts.json.
#pragma once

#include <utility>
#include <vector>

#include "u4d/synth/scene.h"

namespace u4d::synth {

// Surfaces closer than this (metres) are in contact.
constexpr double kContactDistance = 0.05;

// Pairs (a < b) of instance ids of frame.people with two mesh vertices
// (every vertex_stride-th of each) closer than `distance` metres.
std::vector<std::pair<int, int>> PeopleInContact(const SceneFrame& frame,
                                                 double distance = kContactDistance,
                                                 int vertex_stride = 3);

}  // namespace u4d::synth
