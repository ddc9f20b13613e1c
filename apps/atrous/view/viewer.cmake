# The interactive viewer (`atrous view`), included from the top-level CMakeLists.txt after the
# `atrous` executable is defined. Built only when GLFW, OpenGL and imgui (with its GLFW and
# OpenGL 3 backends, as Debian's libimgui-dev ships them) are found; otherwise `atrous view`
# exists and says how to get it.
option(ATROUS_BUILD_VIEWER "Build the interactive viewer when GLFW, OpenGL and imgui are found" ON)

# The viewer's parts without GL: the buffer views' tonemapping (buffer_view.h) and the timings with
# their JSON line (frame_timing.h), over the library's session (include/atrous/view_pipeline.h). A
# library of its own, built with or without the viewer, which the viewer and the tests
# (view_pipeline_test.cpp, view_timing_test.cpp) link.
set(ATROUS_VIEW_CORE_SOURCES ${CMAKE_CURRENT_LIST_DIR}/buffer_view.cpp
    ${CMAKE_CURRENT_LIST_DIR}/frame_timing.cpp)
add_library(atrous_view_core STATIC ${ATROUS_VIEW_CORE_SOURCES})
target_include_directories(atrous_view_core PUBLIC ${CMAKE_CURRENT_LIST_DIR}/..)
target_link_libraries(atrous_view_core PUBLIC atrous_internal)
target_compile_options(atrous_view_core PRIVATE -Wall -Wextra ${ATROUS_CPU_ARCH_FLAGS} -fopenmp-simd)

set(ATROUS_HAVE_VIEWER OFF)
if(ATROUS_BUILD_VIEWER)
  find_package(glfw3 QUIET)
  set(OpenGL_GL_PREFERENCE GLVND)
  find_package(OpenGL QUIET)
  pkg_check_modules(IMGUI QUIET IMPORTED_TARGET imgui)
  if(glfw3_FOUND AND OpenGL_FOUND AND IMGUI_FOUND)
    set(ATROUS_HAVE_VIEWER ON)
  endif()
endif()
message(STATUS "atrous: viewer ${ATROUS_HAVE_VIEWER}")
if(ATROUS_HAVE_VIEWER)
  file(GLOB ATROUS_VIEW_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/*.cpp)
  list(REMOVE_ITEM ATROUS_VIEW_SOURCES ${ATROUS_VIEW_CORE_SOURCES})
  target_sources(atrous_cli PRIVATE ${ATROUS_VIEW_SOURCES})
  target_include_directories(atrous_cli PRIVATE ${CMAKE_CURRENT_LIST_DIR}/..)
  target_compile_definitions(atrous_cli PRIVATE ATROUS_HAVE_VIEWER=1)
  target_link_libraries(atrous_cli PUBLIC atrous_view_core PkgConfig::IMGUI glfw OpenGL::GL ${CMAKE_DL_LIBS})
  if(ATROUS_HAVE_CUDA)
    # CUDA-OpenGL interop for --device cuda (cuda_display.h; cuda_display_stub.cpp otherwise).
    # Its own small library: the executable's host flags (-Wall, -march) are not nvcc's.
    add_library(atrous_view_cuda STATIC ${CMAKE_CURRENT_LIST_DIR}/cuda_display.cu)
    target_include_directories(atrous_view_cuda PRIVATE ${CMAKE_CURRENT_LIST_DIR}/..)
    target_link_libraries(atrous_view_cuda PRIVATE atrous_internal)
    target_link_libraries(atrous_cli PUBLIC atrous_view_cuda)
  endif()
endif()
