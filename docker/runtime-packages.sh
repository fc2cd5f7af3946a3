#!/usr/bin/env bash
# Prints, one a line, the Debian packages a built `limn` needs at run time: the owners of the
# shared libraries it links (its NEEDED entries; apt brings what those need in turn), plus what
# it loads without linking: GLVND's EGL dispatch loads Mesa's EGL (libegl-mesa0), which loads
# llvmpipe (libgl1-mesa-dri). Run in docker/Dockerfile's build stage, where the -dev packages
# that were linked against are installed; the runtime stage installs exactly this list, so it
# never drifts from what the binary links.
#   docker/runtime-packages.sh build/bin/limn
set -euo pipefail
binary=${1:?usage: runtime-packages.sh BINARY}

owner() {  # the package that ships a file, trying both sides of Debian's merged /usr
  local path=$1 alt
  case "$path" in
    /usr/lib/*) alt=${path#/usr} ;;
    /lib/*) alt=/usr$path ;;
    *) alt=$path ;;
  esac
  { dpkg -S "$path" 2>/dev/null || dpkg -S "$alt" 2>/dev/null; } | head -1 | cut -d: -f1
}

packages=(libegl-mesa0 libgl1-mesa-dri)
# Read once: a pipe from ldconfig into an awk that exits early would end in SIGPIPE.
cache=$(ldconfig -p)
while read -r soname; do
  path=$(awk -v lib="$soname" '$1 == lib {print $NF; exit}' <<<"$cache")
  [ -n "$path" ] || { echo "runtime-packages: $soname (needed by $binary) is not installed" >&2; exit 1; }
  package=$(owner "$(readlink -f "$path")")
  [ -n "$package" ] || package=$(owner "$path")
  [ -n "$package" ] || { echo "runtime-packages: no package owns $path ($soname)" >&2; exit 1; }
  packages+=("$package")
done < <(objdump -p "$binary" | awk '$1 == "NEEDED" {print $2}')
printf '%s\n' "${packages[@]}" | sort -u
