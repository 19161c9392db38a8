#pragma once
// Mouse control of the viewer's orbit camera (render/camera.h): left drag orbits, right
// or middle drag pans, the wheel zooms towards the target.
#include "render/camera.h"

namespace softtled {

void camera_orbit(Camera& cam, float dx_px, float dy_px);
void camera_pan(Camera& cam, float dx_px, float dy_px, int viewport_h);
void camera_zoom(Camera& cam, float wheel_steps);

}  // namespace softtled
