#!/bin/sh
# The shared library exports exactly the GA_API functions of the public header: nothing that
# does not start with ga_, and nothing of the header missing.
set -eu
lib=$1
header=$2
# every function in the version node GALPHA_0 (the node itself is an absolute symbol)
unversioned=$(nm -D --defined-only "$lib" | awk '$2 != "A" && $3 !~ /@@GALPHA_0$/ {print $3}')
if [ -n "$unversioned" ]; then
    echo "symbols exported outside the version node GALPHA_0:"; echo "$unversioned"; exit 1
fi
exported=$(nm -D --defined-only "$lib" | awk '$2 != "A" {sub(/@@GALPHA_0$/, "", $3); print $3}' |
           sort)
declared=$(sed -n 's/^GA_API[^(]*[ *]\(ga_[a-z_0-9]*\)(.*/\1/p' "$header" | sort -u)
status=0
foreign=$(printf '%s\n' "$exported" | grep -v '^ga_' || true)
if [ -n "$foreign" ]; then
    echo "symbols exported that are not ga_*:"; echo "$foreign"; status=1
fi
missing=$(printf '%s\n' "$declared" | while read -r f; do
    printf '%s\n' "$exported" | grep -qx "$f" || echo "$f"; done)
if [ -n "$missing" ]; then
    echo "declared in galpha.h but not exported:"; echo "$missing"; status=1
fi
extra=$(printf '%s\n' "$exported" | while read -r f; do
    printf '%s\n' "$declared" | grep -qx "$f" || echo "$f"; done)
if [ -n "$extra" ]; then
    echo "exported but not declared in galpha.h:"; echo "$extra"; status=1
fi
echo "$(printf '%s\n' "$exported" | wc -l) exported symbols, $(printf '%s\n' "$declared" | wc -l) declared"
exit $status
