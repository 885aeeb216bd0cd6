# ctest Package.InstallAndEmbed: `cmake --install` into a temporary prefix, then the embedding
# example (examples/embed) is configured against that prefix with find_package, built and run
# (it checks its own shading kernel against the library's reconstruction and writes a PNG), and
# a consumer is compiled from shadowfilter.pc alone.
#   cmake -DBUILD=<build dir> -DSOURCE=<source> -DWORK=<scratch dir> -DGENERATOR=<generator> -P install_and_embed.cmake
include(${CMAKE_CURRENT_LIST_DIR}/run_step.cmake)
file(REMOVE_RECURSE ${WORK})
set(prefix ${WORK}/prefix)
sf_run_step("install" ${CMAKE_COMMAND} --install ${BUILD} --prefix ${prefix})
foreach(f include/shadowfilter/pipeline.hpp include/shadowfilter/cl/methods/esm.clh
          include/shadowfilter/cl/lookup.clh lib/libshadowfilter.a lib/pkgconfig/shadowfilter.pc
          lib/cmake/shadowfilter/shadowfilterConfig.cmake lib/cmake/shadowfilter/shadowfilterConfigVersion.cmake)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "the install lacks ${f}")
  endif()
endforeach()
file(GLOB_RECURSE installed ${prefix}/*)
set(bytes 0)
foreach(f IN LISTS installed)
  file(SIZE ${f} s)
  math(EXPR bytes "${bytes} + ${s}")
endforeach()
list(LENGTH installed n)
message(STATUS "installed: ${n} files, ${bytes} bytes")

sf_run_step("configure examples/embed against the prefix"
  ${CMAKE_COMMAND} -S ${SOURCE}/examples/embed -B ${WORK}/embed -G ${GENERATOR}
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix})
sf_run_step("build examples/embed" ${CMAKE_COMMAND} --build ${WORK}/embed)
sf_run_step("run examples/embed" ${WORK}/embed/embed_example ${WORK}/embed.png)
message(STATUS "${SF_STEP_OUTPUT}")
if(NOT EXISTS ${WORK}/embed.png)
  message(FATAL_ERROR "the example wrote no PNG")
endif()
file(READ ${WORK}/embed.png head LIMIT 24 HEX)
# PNG signature, IHDR, then width and height (big-endian): 640 x 480.
if(NOT head STREQUAL "89504e470d0a1a0a0000000d4948445200000280000001e0")
  message(FATAL_ERROR "embed.png is not a 640x480 PNG: ${head}")
endif()

# pkg-config: the .pc file is relocatable (prefix from its own location).
find_program(PKG_CONFIG pkg-config REQUIRED)
set(ENV{PKG_CONFIG_PATH} ${prefix}/lib/pkgconfig)
sf_run_step("pkg-config" ${PKG_CONFIG} --cflags --libs shadowfilter)
string(STRIP "${SF_STEP_OUTPUT}" flags)
separate_arguments(flags UNIX_COMMAND "${flags}")
sf_run_step("compile a consumer from shadowfilter.pc"
  c++ -std=c++17 -DCL_HPP_ENABLE_EXCEPTIONS ${SOURCE}/tests/package/consumer.cpp ${flags} -o ${WORK}/consumer_pc)
sf_run_step("run the pkg-config consumer" ${WORK}/consumer_pc)
