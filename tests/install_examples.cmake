# The installed package as an integrator meets it (ctest: InstallAndBuildExamples):
#  1. cmake --install the build into a fresh prefix: shared libraries, both .pc files, the
#     examples, and none of the tools' headers;
#  2. every installed header in one file, with no OpenCL macro set, under -Wall -Wextra
#     -Wpedantic: the compiler prints nothing (no note, no warning);
#  3. configure examples/ against the prefix (the io component too) with the build's compiler and
#     flags (sanitizer builds link their instrumented library): no CMake warning; build it;
#  4. run own_renderer (fog on host images: OpenCL against the scalar path), integrate (its fogged
#     frame must equal the convenience API's, bit for bit), fog_to_exr (EXR written through
#     fogcl::io and read back) and vulkan_exporter (0, or 77: skipped, saying why);
#  5. fogcl::io linked without COMPONENTS io: configuring fails, saying to add it;
#  6. own_renderer and fog_to_exr built from `pkg-config --cflags --libs fogcl` / `fogcl-io`
#     alone, silently, and run;
#  7. docs/library.md names only what the install declares and links (scripts/check_docs.py);
#  8. configure a parent project that add_subdirectory()s fogcl: the library alone, no tools, no
#     install rules, and the parent's build type left alone.
# Arguments (-D): BUILD_DIR SOURCE_DIR WORK_DIR CXX CXX_FLAGS LINKER_FLAGS BUILD_TYPE
cmake_minimum_required(VERSION 3.25)

# run(<command...>) fails the test when the command fails; its output is left in `out`.
macro(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  message("$ ${ARGN}\n${out}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}")
  endif()
endmacro()
# The compiler must say nothing: a note or warning from fogcl's headers is one in every consumer.
function(expect_silent what)
  if(NOT out STREQUAL "")
    message(FATAL_ERROR "${what} printed:\n${out}")
  endif()
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix} --config ${BUILD_TYPE})

# ---- 1. What is installed ----
file(GLOB_RECURSE config ${prefix}/*/fogclConfig.cmake)
file(GLOB_RECURSE pc ${prefix}/*/pkgconfig/fogcl.pc)
file(GLOB_RECURSE pc_io ${prefix}/*/pkgconfig/fogcl-io.pc)
file(GLOB_RECURSE kernels ${prefix}/*.cl)
file(GLOB headers RELATIVE ${prefix}/include ${prefix}/include/fogcl/*.h)
if(NOT config OR NOT pc OR NOT pc_io)
  message(FATAL_ERROR "the install lacks fogclConfig.cmake, fogcl.pc or fogcl-io.pc "
                      "(config: '${config}', pc: '${pc}', '${pc_io}')")
endif()
if(kernels)
  message(FATAL_ERROR "kernels are embedded, yet the install has ${kernels}")
endif()
foreach(tool_header report.h volume_report.h demo_scene.h)
  if(fogcl/${tool_header} IN_LIST headers)
    message(FATAL_ERROR "fogcl/${tool_header} is installed, but its library (the CLI's) is not")
  endif()
endforeach()
foreach(example own_renderer.cpp fog_to_exr.cpp integrate.cpp vulkan_exporter.cpp vulkan_producer.h CMakeLists.txt)
  if(NOT EXISTS ${prefix}/share/doc/fogcl/examples/${example})
    message(FATAL_ERROR "share/doc/fogcl/examples/${example} is not installed")
  endif()
endforeach()
get_filename_component(fogcl_dir ${config} DIRECTORY)
get_filename_component(libdir ${fogcl_dir} DIRECTORY)
get_filename_component(libdir ${libdir} DIRECTORY)
file(GLOB shared_libs ${libdir}/libfogcl.so ${libdir}/libfogcl_io.so)
list(LENGTH shared_libs n_shared)
message("installed: ${headers}; shared libraries: ${shared_libs}")
# nlohmann-json is fogcl::io's build dependency only: no installed file may ask consumers for it.
file(GLOB_RECURSE package_files ${fogcl_dir}/*.cmake ${prefix}/include/*.h)
foreach(f IN LISTS package_files)
  file(READ ${f} text)
  if(text MATCHES "nlohmann")
    message(FATAL_ERROR "${f} names nlohmann-json, a private build dependency of fogcl::io")
  endif()
endforeach()

# ---- 2. Every installed header, no OpenCL macro, -Wall -Wextra -Wpedantic: not a word ----
set(includes "")
foreach(h IN LISTS headers)
  string(APPEND includes "#include <${h}>\n")
endforeach()
file(WRITE ${WORK_DIR}/all_headers.cpp "${includes}int main() { return 0; }\n")
separate_arguments(cxx_flags UNIX_COMMAND "${CXX_FLAGS}")
separate_arguments(linker_flags UNIX_COMMAND "${LINKER_FLAGS}")
run(${CXX} -std=c++17 -Wall -Wextra -Wpedantic -fsyntax-only ${cxx_flags} -I${prefix}/include
    ${WORK_DIR}/all_headers.cpp)
expect_silent("the installed headers (all of them, no OpenCL macro set)")

# ---- 3., 4. The examples through find_package ----
run(${CMAKE_COMMAND} -S ${prefix}/share/doc/fogcl/examples -B ${WORK_DIR}/build -DCMAKE_PREFIX_PATH=${prefix}
    -DCMAKE_BUILD_TYPE=${BUILD_TYPE} -DCMAKE_CXX_COMPILER=${CXX} "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}"
    "-DCMAKE_EXE_LINKER_FLAGS=${LINKER_FLAGS}" -DFOGCL_EXAMPLES_IO=ON)
# (Debian's Imath package says its Python module is missing on every find_package(Imath), as a
# status line: a shared fogcl does not look for Imath; a static one must.)
set(noise "CMake (Warning|Deprecation)")
if(n_shared GREATER 0)
  string(APPEND noise "|Imath::PyImath|file does not exist")
endif()
if(out MATCHES "${noise}")
  message(FATAL_ERROR "configuring the examples against the install warned:\n${out}")
endif()
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build -j 2)
run(${WORK_DIR}/build/own_renderer)
run(${WORK_DIR}/build/integrate 320 180)
# vulkan_exporter where the Vulkan headers and loader are (scripts/setup.sh installs them): its frame
# equal to FogPass::apply's (0), or skipped saying why (77: no OpenCL device that imports GPU
# memory, as PoCL); anything else fails.
if(EXISTS ${WORK_DIR}/build/vulkan_exporter)
  execute_process(COMMAND ${WORK_DIR}/build/vulkan_exporter RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  message("$ vulkan_exporter\n${out}")
  if(NOT (rc EQUAL 0 OR rc EQUAL 77))
    message(FATAL_ERROR "vulkan_exporter failed (${rc})")
  endif()
else()
  message("vulkan_exporter not built: no Vulkan headers and loader (libvulkan-dev)")
endif()
file(MAKE_DIRECTORY ${WORK_DIR}/exr-cmake)
run(${WORK_DIR}/build/fog_to_exr ${WORK_DIR}/exr-cmake)

# ---- 5. fogcl::io without COMPONENTS io ----
set(no_io ${WORK_DIR}/no-io)
file(WRITE ${no_io}/CMakeLists.txt "cmake_minimum_required(VERSION 3.21)
project(no_io LANGUAGES CXX)
find_package(fogcl REQUIRED)
add_executable(app app.cpp)
target_link_libraries(app PRIVATE fogcl::io)
")
file(WRITE ${no_io}/app.cpp "int main() { return 0; }\n")
execute_process(COMMAND ${CMAKE_COMMAND} -S ${no_io} -B ${no_io}/build -DCMAKE_PREFIX_PATH=${prefix}
                        -DCMAKE_CXX_COMPILER=${CXX}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
string(REGEX REPLACE "[ \n]+" " " flat "${out}")
if(rc EQUAL 0 OR NOT flat MATCHES "add COMPONENTS io")
  message(FATAL_ERROR "fogcl::io without COMPONENTS io: expected a failure saying 'add COMPONENTS io', "
                      "got exit ${rc}:\n${out}")
endif()
message("fogcl::io without COMPONENTS io: ${flat}")

# ---- 6. pkg-config alone (shared libraries: no private dependency on the link line) ----
set(ENV{PKG_CONFIG_PATH} ${libdir}/pkgconfig)
set(static_flag)
if(n_shared EQUAL 0)
  set(static_flag --static)  # a static install needs the private dependencies too
endif()
foreach(program IN ITEMS own_renderer:fogcl fog_to_exr:fogcl-io)
  string(REPLACE ":" ";" program "${program}")
  list(GET program 0 name)
  list(GET program 1 package)
  run(pkg-config --cflags --libs ${static_flag} ${package})
  string(STRIP "${out}" flags)
  separate_arguments(flags UNIX_COMMAND "${flags}")
  # The prefix is not on the loader's path: the program records it (or LD_LIBRARY_PATH would do).
  run(${CXX} -std=c++17 -Wall -Wextra -Wpedantic ${cxx_flags} ${prefix}/share/doc/fogcl/examples/${name}.cpp ${flags}
      ${linker_flags} -Wl,-rpath,${libdir} -o ${WORK_DIR}/pc_${name})
  expect_silent("g++ ${name}.cpp $(pkg-config --cflags --libs ${package})")
endforeach()
run(${WORK_DIR}/pc_own_renderer)
file(MAKE_DIRECTORY ${WORK_DIR}/exr-pkgconfig)
run(${WORK_DIR}/pc_fog_to_exr ${WORK_DIR}/exr-pkgconfig)

# ---- 7. The manual against the install ----
find_program(python3 python3 REQUIRED)
run(${python3} ${SOURCE_DIR}/scripts/check_docs.py --installed ${prefix})

# ---- 8. add_subdirectory from a parent project (configure only) ----
set(parent ${WORK_DIR}/parent)
file(WRITE ${parent}/CMakeLists.txt "cmake_minimum_required(VERSION 3.25)
project(parent LANGUAGES CXX)
add_subdirectory(${SOURCE_DIR} fogcl)
foreach(option FOGCL_BUILD_IO FOGCL_BUILD_TESTS FOGCL_BUILD_BENCH FOGCL_BUILD_CLI FOGCL_INSTALL)
  if(\${\${option}})
    message(FATAL_ERROR \"\${option} is ON under add_subdirectory\")
  endif()
endforeach()
foreach(target fogcl_io fogcl_cli fogcl_tests fogcl_bench fogcl_scene)
  if(TARGET \${target})
    message(FATAL_ERROR \"\${target} exists under add_subdirectory\")
  endif()
endforeach()
if(NOT TARGET fogcl::fogcl)
  message(FATAL_ERROR \"no fogcl::fogcl\")
endif()
if(NOT \"\$CACHE{CMAKE_BUILD_TYPE}\" STREQUAL \"\" OR NOT \"\${CMAKE_BUILD_TYPE}\" STREQUAL \"\")
  message(FATAL_ERROR \"fogcl set the parent's build type to '\${CMAKE_BUILD_TYPE}'\")
endif()
message(STATUS \"add_subdirectory: fogcl::fogcl alone, build type untouched\")
")
run(${CMAKE_COMMAND} -S ${parent} -B ${parent}/build -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_BUILD_TYPE=)
