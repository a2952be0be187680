# FindRosbagStorage: ROS 1's bag reader (Debian's librosbag-storage-dev) and
# the sensor_msgs message headers (libsensor-msgs-dev), as one imported target
#   RosbagStorage::rosbag_storage
#
# Why not find_package(rosbag_storage CONFIG): Debian's catkin-generated config
# pulls in ROS 2's pluginlib config, which runs ament's Python templating at
# configure time, and its pkg-config file requires a pluginlib.pc Debian does
# not ship. bag.h includes pluginlib, which includes class_loader, rcpputils,
# rcutils and ament_index_cpp, each installed under its own folder of
# /usr/include: those folders are found here by the header each provides.
include(FindPackageHandleStandardArgs)

find_path(RosbagStorage_INCLUDE_DIR rosbag/bag.h)
find_path(RosbagStorage_SENSOR_MSGS_INCLUDE_DIR sensor_msgs/Image.h)
set(_rosbag_header_deps
  pluginlib/class_loader.hpp:pluginlib
  class_loader/multi_library_class_loader.hpp:class_loader
  rcpputils/shared_library.hpp:rcpputils
  rcutils/types.h:rcutils
  ament_index_cpp/get_package_prefix.hpp:ament_index_cpp)
set(_rosbag_dep_dirs)
set(_rosbag_dep_vars)
foreach(dep ${_rosbag_header_deps})
  string(REPLACE ":" ";" dep ${dep})
  list(GET dep 0 header)
  list(GET dep 1 suffix)
  string(TOUPPER ${suffix} var)
  find_path(RosbagStorage_${var}_INCLUDE_DIR ${header} PATH_SUFFIXES ${suffix})
  list(APPEND _rosbag_dep_dirs ${RosbagStorage_${var}_INCLUDE_DIR})
  list(APPEND _rosbag_dep_vars RosbagStorage_${var}_INCLUDE_DIR)
endforeach()

set(_rosbag_libs)
set(_rosbag_lib_vars)
foreach(lib rosbag_storage roscpp_serialization rostime cpp_common console_bridge)
  find_library(RosbagStorage_${lib}_LIBRARY ${lib})
  list(APPEND _rosbag_libs ${RosbagStorage_${lib}_LIBRARY})
  list(APPEND _rosbag_lib_vars RosbagStorage_${lib}_LIBRARY)
endforeach()

find_package_handle_standard_args(RosbagStorage
  REQUIRED_VARS RosbagStorage_INCLUDE_DIR RosbagStorage_SENSOR_MSGS_INCLUDE_DIR ${_rosbag_dep_vars} ${_rosbag_lib_vars}
  REASON_FAILURE_MESSAGE "install Debian's librosbag-storage-dev and libsensor-msgs-dev (scripts/setup.sh does)")

if(RosbagStorage_FOUND AND NOT TARGET RosbagStorage::rosbag_storage)
  add_library(RosbagStorage::rosbag_storage INTERFACE IMPORTED)
  set_target_properties(RosbagStorage::rosbag_storage PROPERTIES
    INTERFACE_SYSTEM_INCLUDE_DIRECTORIES
      "${RosbagStorage_INCLUDE_DIR};${RosbagStorage_SENSOR_MSGS_INCLUDE_DIR};${_rosbag_dep_dirs}"
    INTERFACE_INCLUDE_DIRECTORIES
      "${RosbagStorage_INCLUDE_DIR};${RosbagStorage_SENSOR_MSGS_INCLUDE_DIR};${_rosbag_dep_dirs}"
    INTERFACE_LINK_LIBRARIES "${_rosbag_libs}")
endif()
mark_as_advanced(RosbagStorage_INCLUDE_DIR RosbagStorage_SENSOR_MSGS_INCLUDE_DIR ${_rosbag_dep_vars} ${_rosbag_lib_vars})
