# Environment for building and running hglasm_odometry with Debian's ROS 1 (sourced by the scripts).
# - /usr/bin first: a python3 earlier on PATH (pyenv, venvs) lacks rospy/catkin_pkg.
# - ROS_HOSTNAME=localhost: ROS networking over loopback, whatever the machine's hostname resolves to.
# - ROS_HOME inside the checkout: logs and test results stay out of ~/.ros.
export PATH=/usr/bin:$PATH
export ROS_HOSTNAME=localhost
HGLASM_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export HGLASM_ROOT
export ROS_HOME="${ROS_HOME:-$HGLASM_ROOT/.ros_home}"
HGLASM_BUILD="${HGLASM_BUILD:-$HGLASM_ROOT/build}"
export HGLASM_BUILD
HGLASM_CMAKE_ARGS=(-DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3
                   -DCATKIN_DEVEL_PREFIX="$HGLASM_BUILD/devel" -DCMAKE_BUILD_TYPE=Release)

# Configures (once) and builds the catkin package with plain CMake into $HGLASM_BUILD.
hglasm_build() {
  if [ ! -f "$HGLASM_BUILD/CMakeCache.txt" ]; then
    cmake -S "$HGLASM_ROOT" -B "$HGLASM_BUILD" "${HGLASM_CMAKE_ARGS[@]}" || return 1
  fi
  cmake --build "$HGLASM_BUILD" -j"$(nproc)" "$@"
}
