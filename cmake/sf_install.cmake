# install() rules and the CMake package: `cmake --install BUILD --prefix P` gives
#   P/include/shadowfilter/*.hpp       the C++ API (core library)
#   P/include/shadowfilter/cl/...      OpenCL C headers for a caller's own kernels (docs/embedding.md)
#   P/lib/libshadowfilter.a            the core library (OpenCL only)
#   P/lib/cmake/shadowfilter/          shadowfilterConfig.cmake, version file, exported targets
#   P/lib/pkgconfig/shadowfilter.pc
#   P/bin/shadowfilter                 the command, when SF_BUILD_CLI is on
include(CMakePackageConfigHelpers)
set(SF_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/shadowfilter)

install(TARGETS shadowfilter EXPORT shadowfilterTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/host/include/shadowfilter
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.hpp")
# The kernels' headers (methods, lookups, storage, helpers); the .cl programs stay embedded.
install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/kernels/
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/shadowfilter/cl FILES_MATCHING PATTERN "*.clh")
install(EXPORT shadowfilterTargets NAMESPACE shadowfilter:: DESTINATION ${SF_CMAKE_DIR})

configure_package_config_file(${CMAKE_CURRENT_SOURCE_DIR}/cmake/shadowfilterConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/shadowfilterConfig.cmake
  INSTALL_DESTINATION ${SF_CMAKE_DIR}
  PATH_VARS CMAKE_INSTALL_INCLUDEDIR)
# 0.x: a minor version may change the API, so only the same minor version is compatible.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/shadowfilterConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/shadowfilterConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/shadowfilterConfigVersion.cmake
        DESTINATION ${SF_CMAKE_DIR})

# An SF_SANITIZE library needs the sanitizer runtimes at the consumer's link, as the CMake
# target's link options say.
set(SF_PC_EXTRA_LIBS "")
if(SF_SANITIZE)
  list(JOIN SF_SANITIZE_LINK_FLAGS " " SF_PC_EXTRA_LIBS)
  string(PREPEND SF_PC_EXTRA_LIBS " ")
endif()
file(RELATIVE_PATH SF_PC_TO_PREFIX "/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/")
configure_file(${CMAKE_CURRENT_SOURCE_DIR}/cmake/shadowfilter.pc.in
               ${CMAKE_CURRENT_BINARY_DIR}/shadowfilter.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/shadowfilter.pc
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

if(SF_BUILD_CLI)
  install(TARGETS shadowfilter_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
