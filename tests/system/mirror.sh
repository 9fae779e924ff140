# Sourced by the system tests (run.sh, debian13.sh): find_mirror SUITE prints the Debian mirror
# this machine's apt uses for SUITE, or fails. CARACARA_SYSTEST_MIRROR overrides it.
# deb822 files first (Debian 12's default), then one-line sources. Only a "deb" source of the
# suite itself counts (not -updates, -security, or another distribution).
find_mirror() {
  local suite=$1
  if [ -n "${CARACARA_SYSTEST_MIRROR:-}" ]; then
    echo "$CARACARA_SYSTEST_MIRROR"
    return
  fi
  local f uri
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    uri=$(awk -v suite="$suite" '
      BEGIN { RS = ""; FS = "\n" }
      {
        types = ""; uris = ""; suites = ""; enabled = "yes"
        for (i = 1; i <= NF; i++) {
          line = $i
          if (line ~ /^[ \t]*#/) continue
          split(line, kv, ":")
          key = tolower(kv[1]); val = substr(line, length(kv[1]) + 2)
          gsub(/^[ \t]+|[ \t]+$/, "", val)
          if (key == "types") types = val
          else if (key == "uris") uris = val
          else if (key == "suites") suites = val
          else if (key == "enabled") enabled = tolower(val)
        }
        if (enabled == "no") next
        if ((" " types " ") !~ / deb /) next
        if ((" " suites " ") !~ (" " suite " ")) next
        split(uris, u, /[ \t]+/)
        print u[1]; exit
      }' "$f")
    if [[ $uri =~ ^(https?|file):// ]]; then echo "$uri"; return; fi
  done
  for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    [ -f "$f" ] || continue
    uri=$(awk -v suite="$suite" '
      $1 == "deb" {
        i = 2
        if ($i ~ /^\[/) { while ($i !~ /\]$/ && i < NF) i++; i++ }
        if ($(i + 1) == suite) { print $i; exit }
      }' "$f")
    if [[ $uri =~ ^(https?|file):// ]]; then echo "$uri"; return; fi
  done
  # Not listed (Debian 12's sources name only bookworm): the archive that serves this machine's
  # own release serves the other releases too.
  local own
  own=$(. /etc/os-release && echo "${VERSION_CODENAME:-}")
  if [ -n "$own" ] && [ "$own" != "$suite" ]; then
    find_mirror "$own"
    return
  fi
  return 1
}
