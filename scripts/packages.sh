# Sourced by setup.sh and fuzz.sh: ensure_packages PKG... installs with apt-get (via sudo
# when not root) the Debian packages among its arguments that are not installed yet.
ensure_packages() {
  local missing="" p SUDO=""
  for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
  done
  [ -z "$missing" ] && return 0
  echo "$(basename "$0"): installing missing Debian packages:$missing"
  [ "$(id -u)" -ne 0 ] && SUDO=sudo
  $SUDO apt-get update -qq
  # shellcheck disable=SC2086
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing
}
