# robot_lab: build a kit interface package for Python only (CMAKE_PROJECT_INCLUDE).
#
# rclpy loads the C type supports (rosidl_typesupport_c, introspection_c, fastrtps_c); the
# C++ ones serve rclcpp, which PyPI does not have, and were half of the build's time.
# Found here, right after project(), the generators register themselves; the package's own
# find_package(rosidl_default_generators) is then a no-op (ament's include guard), so its
# rosidl_generate_interfaces() runs the generators left in the list.
find_package(rosidl_default_generators REQUIRED)
list(FILTER AMENT_EXTENSIONS_rosidl_generate_idl_interfaces EXCLUDE REGEX
     "^rosidl_(generator_cpp|typesupport_cpp|typesupport_introspection_cpp|typesupport_fastrtps_cpp):")
