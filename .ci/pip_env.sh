# Sourced (from the repository's root) by every .ci script that runs pip: quiet about itself, and
# patient with the package registry. pip retries a request 5 times by default, ~8 s of urllib3's
# doubling backoff in all: a registry resetting connections for longer (seen: 5 resets in a row
# on ros-jazzy-rclpy's index page, a red CI) fails the install. 10 retries wait ~4 min in all.
export PIP_DISABLE_PIP_VERSION_CHECK=1 PIP_ROOT_USER_ACTION=ignore PIP_RETRIES="${PIP_RETRIES:-10}"
