// GLSL sources of the rasteriser's two programs. The shading constants are generated from
// render/core/shading.h, so the fragment shader and shading::shade() cannot drift apart.
#pragma once

#include <string>

namespace limn::render::raster {

// The surface program: writes colour (location 0, shaded as shading::shade() does, alpha 1),
// linear depth (location 1) and the world-space shading normal (location 2).
// Uniforms: uViewProjection, uEye, uForward, uPerspective, uSmooth.
std::string surfaceVertexShader();
std::string surfaceFragmentShader();

// The solid program: one uniform colour uColor at location 0 (wire edges, coverage).
// Uniform: uViewProjection.
std::string solidVertexShader();
std::string solidFragmentShader();

// A float as a GLSL literal that reads back to the same float ("0.800000012", "40.0").
std::string glslFloat(float value);

}  // namespace limn::render::raster
