# rcfile of a JupyterLab terminal started by ./kit start / ./kit lab: a ROS 2 terminal.
# Read by an interactive non-login bash (see jupyter_server_config.py), so Debian's
# /etc/profile never resets PATH behind the kit's back.

[ -f /etc/bash.bashrc ] && . /etc/bash.bashrc
[ -f "$HOME/.bashrc" ] && . "$HOME/.bashrc"

# The kit's venv first on PATH: ros2, colcon, robot-lab, python with rclpy.
if [ -n "${ROBOT_LAB_VENV:-}" ] && [ -f "$ROBOT_LAB_VENV/bin/activate" ]; then
  VIRTUAL_ENV_DISABLE_PROMPT=1 . "$ROBOT_LAB_VENV/bin/activate"
  # The venv as ROS underlay (what /opt/ros/jazzy/setup.bash is): colcon builds interfaces.
  [ -f "$ROBOT_LAB_VENV/setup.bash" ] && . "$ROBOT_LAB_VENV/setup.bash"
fi

export ROS_AUTOMATIC_DISCOVERY_RANGE=${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST}
export ROBOT_LAB_WORKSPACE=${ROBOT_LAB_WORKSPACE:-$HOME/robot_lab_ws}
# The student's own ROS domain, the one their notebooks use (unless they set one).
if [ -z "${ROS_DOMAIN_ID:-}" ]; then
  if _robot_lab_domain=$(python -c 'from robot_lab.domain import domain_for; print(domain_for())' 2>/dev/null); then
    export ROS_DOMAIN_ID=$_robot_lab_domain
  fi
  unset _robot_lab_domain
fi

# Start in the folder the file browser shows (the student's course copy). A terminal opened
# without a folder starts in the server's own working directory (for ./kit, the repository):
# anything outside the server's root is not where the student works.
_robot_lab_root=${JUPYTER_SERVER_ROOT:-${ROBOT_LAB_COURSE:-}}
if [ -n "$_robot_lab_root" ] && [ -d "$_robot_lab_root" ]; then
  case "$(pwd -P)/" in
    "$(cd "$_robot_lab_root" && pwd -P)"/*) ;;
    *) cd "$_robot_lab_root" || true ;;
  esac
fi
unset _robot_lab_root

if [ -z "${ROBOT_LAB_QUIET:-}" ]; then
  printf 'ROS 2 Jazzy terminal (robot_lab): ROS_DOMAIN_ID=%s, workspace %s\n' \
    "${ROS_DOMAIN_ID:-0}" "${ROBOT_LAB_WORKSPACE/#$HOME/\~}"
  # --symlink-install, as the notebooks build: a plain `colcon build` would copy the files
  # instead, and later edits would be ignored until the next build.
  printf 'your packages: cd %s && colcon build --symlink-install && source install/setup.bash\n' \
    "${ROBOT_LAB_WORKSPACE/#$HOME/\~}"
fi
