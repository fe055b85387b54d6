# SPDX-License-Identifier: MIT
# Sourced by every script in scripts/: `pour_script_cli "$ROOT/scripts/NAME.sh" "$@"` answers --help (the
# script's header comment, from its third line to the first line that is not a comment) and --version (the
# project's, from tools/pyproject.toml) with exit 0, before the script does any work.
pour_script_cli() {
  local script=$1
  shift
  case "${1:-}" in
    -h|--help)
      awk 'NR >= 3 { if (!/^#/) exit; sub(/^# ?/, ""); print }' "$script"
      exit 0 ;;
    --version)
      echo "$(basename "$script") (pour) $(sed -n 's/^version = "\(.*\)"$/\1/p' \
        "$(dirname "$script")/../tools/pyproject.toml")"
      exit 0 ;;
  esac
}
