// GLSL sources of the rasteriser's programs. The shading constants are generated from
// render/core/shading.h, so the fragment shader and shading::shade() cannot drift apart.
#pragma once

#include <string>

namespace limn::render::raster {

// The surface program: writes colour (location 0, shaded as shading::shade() does, alpha 1),
// linear depth (location 1) and the world-space shading normal (location 2). The normal is the
// face normal, or the interpolated vertex normal (uSmooth), or the normal map's bilinear sample
// at the interpolated texture coordinate (uNormalMap), renormalised.
// Attributes: aPosition (0), aNormal (1), aTexcoord (2).
// Uniforms: uViewProjection, uEye, uForward, uPerspective, uSmooth, uNormalMap, uNormalTexture.
std::string surfaceVertexShader();
std::string surfaceFragmentShader();

// The solid program: one uniform colour uColor at location 0 (wire edges, coverage).
// Uniform: uViewProjection.
std::string solidVertexShader();
std::string solidFragmentShader();

// The line program: overlay segments widened into screen-space quads (OpenGL core has no wide
// lines) by a geometry shader, each written with its segment's RGBA at location 3.
// Attributes: aPosition (0), aColor (1, normalised bytes). Uniforms: uViewProjection, uViewport
// (the tile's size in pixels), uHalfWidth (pixels; the quad is 2 * uHalfWidth wide and extends
// uHalfWidth past each end so polylines have no gaps at their joints), and uEye, uForward,
// uPerspective, uBias: each point is moved towards the eye along its view ray before projection,
// by the fraction uBias of its distance (perspective) or uBias world units (orthographic).
std::string lineVertexShader();
std::string lineGeometryShader();
std::string lineFragmentShader();

// A float as a GLSL literal that reads back to the same float ("0.800000012", "40.0").
std::string glslFloat(float value);

}  // namespace limn::render::raster
