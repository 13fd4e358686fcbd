#pragma once
// Camera navigation of the viewer, on CameraSettings (core/camera.h): fly
// (turn the view about the eye, move eye and look-at point together) and orbit
// (turn the eye about the look-at point, dolly towards it). Pure functions,
// tested without a window.
#include "core/camera.h"

namespace nebula::viewer {

// Turns the view about the eye: yaw about the camera's up vector, pitch about
// its right vector (radians); the look-at point keeps its distance.
CameraSettings fly_turn(const CameraSettings& c, double yaw, double pitch);

// Moves eye and look-at point together along the view (forward), right and up
// directions by these distances (parsecs).
CameraSettings fly_move(const CameraSettings& c, double forward, double right, double up);

// Turns the eye about the look-at point: yaw about the camera's up vector,
// pitch about its right vector (radians); the distance is kept. The pitch
// stops 1 degree short of the up vector (the view would lose its up).
CameraSettings orbit(const CameraSettings& c, double yaw, double pitch);

// Moves the eye towards the look-at point to `factor` times its distance (> 0).
CameraSettings dolly(const CameraSettings& c, double factor);

}  // namespace nebula::viewer
