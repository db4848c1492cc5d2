# The installed package as an integrator meets it (ctest: InstallAndBuildExamples):
#  1. cmake --install the build into a fresh prefix;
#  2. configure + build examples/ against it (-Dfogcl_DIR=..., the io component too) with the
#     build's compiler and flags (sanitizer builds link their instrumented library);
#  3. run `integrate` (its fogged frame must equal the convenience API's, bit for bit) and the
#     io component check;
#  4. build and run a program from `pkg-config --cflags --libs fogcl` alone;
#  5. configure a parent project that add_subdirectory()s fogcl: the library alone, no tools, no
#     install rules, and the parent's build type left alone.
# Arguments (-D): BUILD_DIR SOURCE_DIR WORK_DIR CXX CXX_FLAGS LINKER_FLAGS BUILD_TYPE
cmake_minimum_required(VERSION 3.25)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  message("$ ${ARGN}\n${out}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}")
  endif()
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix} --config ${BUILD_TYPE})

file(GLOB_RECURSE config ${prefix}/*/fogclConfig.cmake)
file(GLOB_RECURSE pc ${prefix}/*/fogcl.pc)
file(GLOB_RECURSE kernels ${prefix}/*.cl)
if(NOT config OR NOT pc)
  message(FATAL_ERROR "the install lacks fogclConfig.cmake or fogcl.pc (config: '${config}', pc: '${pc}')")
endif()
if(kernels)
  message(FATAL_ERROR "kernels are embedded, yet the install has ${kernels}")
endif()
get_filename_component(fogcl_dir ${config} DIRECTORY)
# nlohmann-json is fogcl::io's build dependency only: no installed file may ask consumers for it.
file(GLOB_RECURSE package_files ${fogcl_dir}/*.cmake ${prefix}/include/*.h)
foreach(f IN LISTS package_files)
  file(READ ${f} text)
  if(text MATCHES "nlohmann")
    message(FATAL_ERROR "${f} names nlohmann-json, a private build dependency of fogcl::io")
  endif()
endforeach()

run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples -B ${WORK_DIR}/build -Dfogcl_DIR=${fogcl_dir}
    -DCMAKE_BUILD_TYPE=${BUILD_TYPE} -DCMAKE_CXX_COMPILER=${CXX} "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}"
    "-DCMAKE_EXE_LINKER_FLAGS=${LINKER_FLAGS}" -DFOGCL_EXAMPLES_IO=ON)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build -j 2)
run(${WORK_DIR}/build/integrate 320 180)
run(${WORK_DIR}/build/io_component_check)

# pkg-config alone (the static library's private dependencies through --static).
get_filename_component(pc_dir ${pc} DIRECTORY)
set(ENV{PKG_CONFIG_PATH} ${pc_dir})
execute_process(COMMAND pkg-config --cflags --libs --static fogcl OUTPUT_VARIABLE flags RESULT_VARIABLE rc
                OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pkg-config --cflags --libs fogcl failed (${rc})")
endif()
message("pkg-config: ${flags}")
separate_arguments(flags UNIX_COMMAND "${flags}")
separate_arguments(cxx_flags UNIX_COMMAND "${CXX_FLAGS} ${LINKER_FLAGS}")
run(${CXX} -std=c++17 -DCL_TARGET_OPENCL_VERSION=300 ${cxx_flags} ${SOURCE_DIR}/examples/compile_checks/pkgconfig_check.cpp ${flags}
    -o ${WORK_DIR}/pkgconfig_check)
run(${WORK_DIR}/pkgconfig_check)

# add_subdirectory from a parent project (configure only).
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
