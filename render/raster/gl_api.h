// The OpenGL 4.5 core API as limn uses it: prototypes straight from <GL/glcorearb.h>, resolved
// by GLVND's libOpenGL at link time, so no loader library is needed. Include this header
// instead of any other GL header, and never before one (GL_GLEXT_PROTOTYPES must come first).
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/glcorearb.h>
