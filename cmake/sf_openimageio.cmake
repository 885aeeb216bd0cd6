# sf::OpenImageIO: OpenImageIO's headers and libraries, found through its pkg-config file.
#
# Not through OpenImageIO's CMake package: Debian 12's OpenImageIOTargets.cmake lists
# /usr/include/opencv4 in the imported target's include directories, a path that exists only
# once libopencv-dev is installed, so configuring fails on any machine without OpenCV
# ("Imported target OpenImageIO::OpenImageIO includes non-existent path"). shadowfilter uses no
# OpenCV through OpenImageIO; the .pc file names exactly what its headers and libraries need.
find_package(PkgConfig REQUIRED)
pkg_check_modules(SF_OIIO REQUIRED IMPORTED_TARGET OpenImageIO>=2.2)
if(NOT TARGET sf::OpenImageIO)
  add_library(sf::OpenImageIO INTERFACE IMPORTED)
  target_link_libraries(sf::OpenImageIO INTERFACE PkgConfig::SF_OIIO)
endif()
message(STATUS "OpenImageIO ${SF_OIIO_VERSION} (pkg-config)")
