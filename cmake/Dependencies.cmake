# All dependencies come from Debian 12 packages (see scripts/setup.sh).
find_package(Threads REQUIRED)
find_package(Boost 1.74 REQUIRED)
find_package(embree 3.13 REQUIRED)
find_package(GTest REQUIRED)
include(GoogleTest)
find_package(benchmark QUIET)

# OpenSubdiv: Debian's OpenSubdivConfig.cmake looks for static archives that are not shipped,
# so the imported target is made by hand.
find_path(OSD_INCLUDE_DIR opensubdiv/version.h REQUIRED)
find_library(OSD_CPU_LIBRARY osdCPU REQUIRED)
add_library(opensubdiv INTERFACE)
target_include_directories(opensubdiv INTERFACE ${OSD_INCLUDE_DIR})
target_link_libraries(opensubdiv INTERFACE ${OSD_CPU_LIBRARY})
# libosdGPU for the GLSL source of Osd's patch basis (the patches' tessellation shaders); it
# links no GL library itself.
find_library(OSD_GPU_LIBRARY osdGPU REQUIRED)
add_library(opensubdiv_gpu INTERFACE)
target_link_libraries(opensubdiv_gpu INTERFACE opensubdiv ${OSD_GPU_LIBRARY})

# OpenImageIO: its exported target names /usr/include/opencv4, which does not exist unless
# OpenCV is installed, and CMake refuses to generate with a missing include directory.
find_package(OpenImageIO 2.4 CONFIG REQUIRED)
get_target_property(_oiio_includes OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
list(FILTER _oiio_includes EXCLUDE REGEX "opencv")
set_target_properties(OpenImageIO::OpenImageIO PROPERTIES
  INTERFACE_INCLUDE_DIRECTORIES "${_oiio_includes}")

# RapidJSON ships only include directories.
find_package(RapidJSON REQUIRED)
# spdlog (Debian's, built against the system fmt): the server's request log.
find_package(spdlog REQUIRED)
add_library(rapidjson INTERFACE)
target_include_directories(rapidjson INTERFACE ${RAPIDJSON_INCLUDE_DIRS})

# tinyobjloader: header plus library.
find_path(TINYOBJ_INCLUDE_DIR tiny_obj_loader.h REQUIRED)
find_library(TINYOBJ_LIBRARY tinyobjloader REQUIRED)
add_library(tinyobjloader_lib INTERFACE)
target_include_directories(tinyobjloader_lib INTERFACE ${TINYOBJ_INCLUDE_DIR})
target_link_libraries(tinyobjloader_lib INTERFACE ${TINYOBJ_LIBRARY})

# Headless OpenGL through EGL (GLVND).
set(OpenGL_GL_PREFERENCE GLVND)
find_package(OpenGL REQUIRED COMPONENTS OpenGL EGL)

# CLI11 (header only): the options of `limn batch`.
find_package(CLI11 2.1 CONFIG REQUIRED)

# Assimp (formats/: mesh files in): Debian's assimpTargets.cmake names draco::draco and minizip
# targets that its package does not define, so the imported target is made by hand.
find_path(ASSIMP_INCLUDE_DIR assimp/Importer.hpp REQUIRED)
find_library(ASSIMP_LIBRARY assimp REQUIRED)
add_library(assimp_lib INTERFACE)
target_include_directories(assimp_lib INTERFACE ${ASSIMP_INCLUDE_DIR})
target_link_libraries(assimp_lib INTERFACE ${ASSIMP_LIBRARY})
