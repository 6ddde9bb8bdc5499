#!/bin/sh
# The install command of docs/PYTHON.md in a fresh virtual environment (Debian's packages only, no
# index), then `import apparent` from another folder: its version must be the project's.
# Usage: install_test.sh PYTHON SOURCE_DIR BUILD_DIR VERSION
set -eu
python=$1 source=$2 build=$3 version=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$python" -m venv --system-site-packages "$work/venv"
APPARENT_BUILD_DIR="$build" "$work/venv/bin/pip" install --quiet --no-index --no-build-isolation "$source"
mkdir "$work/elsewhere"
cd "$work/elsewhere"
got=$("$work/venv/bin/python" -c "import apparent; print(apparent.__version__)")
where=$("$work/venv/bin/python" -c "import apparent; print(apparent.__file__)")
echo "apparent $got from $where"
case "$where" in "$work/venv/"*) ;; *) echo "not the installed copy: $where"; exit 1 ;; esac
[ "$got" = "$version" ] || { echo "version $got, expected $version"; exit 1; }
