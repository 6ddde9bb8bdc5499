// `apparent figure --frame-objects`: the camera aimed and its field of view set so that the
// apparent shapes of the objects fill the panels. The shapes are the mesh pipeline's (frame_cut.h)
// for every row's model at every column's frame; each of their points is seen from the camera
// (at scene.camera.position in the frame the outputs are in, also for a moving camera: the finite
// model's sheared outputs put it there too, lightcone.h ViewSurface) along the unit direction d.
// With the camera basis forward f, right r, up u (up from camera.up, as the raytracer's), d meets
// the image plane at distance 1 at (x, y) = (d.r, d.u) / d.f, where pixelDirection puts it. The
// forward direction starts as the mean of the directions and is turned, kFramingTurns times,
// towards the centre of the points' (x, y) box: f' = f + x_c r + y_c u, normalised; then the
// vertical half-height of the view is h = (1 + kFramingMargin) max(max |y|, max |x| height / width)
// and fov_deg = 2 atan(h), so that every point lies inside the picture with the margin to spare.
#pragma once

#include <vector>

#include "pipeline/input/status.h"
#include "pipeline/stage/stage.h"

namespace apparent {

constexpr double kFramingMargin = 0.05;  // of the half-extent, on each side of the limiting axis
constexpr int kFramingTurns = 4;
constexpr double kMaxFramingFovDeg = 170;

// The objects framed: the ones that move in the lab (objects at rest, such as a stage floor or a
// backdrop, are left out), or every object when none moves; never a mirror.
std::vector<size_t> framedObjects(const Stage& stage);

// Sets camera->look_at (at the distance it had) and camera->fov_deg as above for a picture of
// width x height (a perspective camera). Failure (one line): an orthographic camera; nothing of the framed objects is seen in those frames, a
// point lies more than 85 degrees off the centre, or the view would need more than
// kMaxFramingFovDeg; a frame the mesh pipeline refuses (its message).
Status frameObjects(const Stage& stage, const std::vector<Model>& models, const std::vector<long long>& frames,
                    int width, int height, CameraSpec* camera);

}  // namespace apparent
