# The system test's checks of the Debian packages (run.sh --debs DIR), sourced by check.sh,
# whose helpers they use: the install with apt-get, an upgrade while the thrusters run, and
# the purge. The packages are in /systest-debs; /systest-debs-next holds the same packages one
# version up (run.sh made them by changing only the version).
NEXT=/systest-debs-next
# What the purge must take away again: the file system before the install, less what changes
# anyway (logs, apt's and dpkg's own state, caches, the test's own files).
fs_list() {
  find / -xdev \( -path /proc -o -path /sys -o -path /dev -o -path /run -o -path /tmp \
    -o -path /var/tmp -o -path /var/log -o -path /var/cache -o -path /var/lib/apt \
    -o -path /var/lib/dpkg -o -path /root -o -path '/systest-*' \) -prune -o -print | sort
}
apt_get() {
  DEBIAN_FRONTEND=noninteractive apt-get -y -o Dpkg::Use-Pty=0 --no-install-recommends "$@" \
    >>"$out/apt.log" 2>&1
}
# The newest caracara-sim/caracarad process ids.
pid_of() { unit "$1" MainPID; }
# zeros_hold_since INDEX: in the wire log since INDEX, no thruster got anything but a zero
# order once it had got a zero (SPEED 0x80 or 0x7F): nothing started them again.
zeros_hold_since() {
  busctl call $S $SP $S GetWireLog t "$1" | grep -oE '"i2c" [0-9]+ false 3 [0-9]+ 100 [0-9]+' |
    awk '{ if ($5 == 128 || $5 == 127) z[$2] = 1; else if ($2 in z) bad++ }
         END { if (bad) print bad " non-zero orders after a zero"; exit bad > 0 }'
}
no_order_but_zero_since() {
  ! busctl call $S $SP $S GetWireLog t "$1" | grep -oE '"i2c" [0-9]+ false 3 [0-9]+ 100 [0-9]+' |
    awk '$5 != 128 && $5 != 127' | grep -q .
}
killed_by_start() { [ "$(state)" = killed ] && [ "$(prop $V $VP $V KillSource)" = start ]; }
zero_and_killed() { all_zero && killed_by_start; }
# reap_ctl: waits for the caracaractl started by hold_all to end; its exit status in ctl_rc.
ctl_ended() { ! kill -0 "$ctl_pid" 2>/dev/null || grep -q '^State:[[:space:]]*Z' "/proc/$ctl_pid/status" 2>/dev/null; }
reap_ctl() {
  ctl_rc=none
  if wait_until 15 ctl_ended; then
    wait "$ctl_pid"
    ctl_rc=$?
  fi
  stop_ctl
}

debs_install() {
  fs_list >/root/fs-before.txt
  local t rc=0
  t=$(now_ms)
  (cd "$DEBS" && apt_get install ./caracarad_*.deb ./caracara-sim_*.deb) || rc=$?
  if [ "$rc" = 0 ]; then
    pass "apt-get install ./caracarad_*.deb ./caracara-sim_*.deb ($(cd "$DEBS" && echo *.deb)) in $(($(now_ms) - t)) ms"
  else
    fail "apt-get install ./caracarad_*.deb ./caracara-sim_*.deb (exit $rc)"
    tail -n 40 "$out/apt.log"
  fi
  dpkg -L caracarad caracara-sim >/root/debs-files.txt
  check "no file of the packages under /usr/local" bash -c '! grep -q "^/usr/local" /root/debs-files.txt'
  check "no conffile and no $CONF: the daemon runs on its built-in defaults" \
    bash -c '[ ! -e "$1" ] && [ -z "$(dpkg-query -W -f="\${Conffiles}" caracarad caracara-sim)" ]' _ "$CONF"
  check "the postinst created the caracara user and group, caracara-bridge and caracara-ros in the group, and caracara-io with only caracara in it" \
    users_and_groups
  check "the postinst enabled and started caracarad.service and caracara-sim.service" \
    bash -c 'systemctl is-enabled -q caracarad caracara-sim && systemctl is-active -q caracarad caracara-sim'
  check "caracara-sim's drop-in puts caracarad in sim mode" \
    bash -c 'systemctl show -p ExecStart caracarad | grep -q -- "--hardware=sim:/run/caracara-sim/sim.sock"'
  check "the daemon owns $V (the bus read the policy again once the user existed)" busctl status $V
  check "the installed daemon came up killed (kill source start)" killed_by_start
  check "the simulator runs on the built-in vehicle (no $CONF): thruster/7 exists" \
    bash -c 'busctl tree --list "$1" | grep -qx "$2/thruster/7"' _ $S $SP
}

debs_upgrade() {
  local pid sim_pid idx rc=0 v0
  # (a) The same version again (apt-get install --reinstall), while a pilot holds every
  # thruster at SPEED $spd_all with caracaractl: postinst restarts caracarad.
  arm
  check "upgrade: all eight thrusters driven before it" drive_all
  pid=$(pid_of caracarad)
  sim_pid=$(pid_of caracara-sim)
  idx=$(wire_next)
  (cd "$DEBS" && apt_get install --reinstall ./caracarad_*.deb) || rc=$?
  check "apt-get install --reinstall caracarad while the thrusters run (exit $rc)" [ "$rc" = 0 ]
  check "the reinstall restarted caracarad (pid $pid -> $(pid_of caracarad)), the simulator kept running" \
    bash -c '[ "$(systemctl show -p MainPID --value caracarad)" != "$1" ] && systemctl is-active -q caracarad &&
             [ "$(systemctl show -p MainPID --value caracara-sim)" = "$2" ]' _ "$pid" "$sim_pid"
  check "every thruster got zero orders during the restart" every_thruster_zeroed_since "$idx"
  check "no thruster was ordered anything but zero after its first zero" zeros_hold_since "$idx"
  check "after the reinstall every thruster is at zero ($(speeds))" all_zero
  check "the restarted daemon is killed (kill source start)" killed_by_start
  reap_ctl
  info "caracaractl, holding across the restart, ended with status $ctl_rc: $(tail -n 1 "$out/caracaractl.log")"
  check "caracaractl's commands were refused after the restart (it ended with status 1 or 3, not 0)" \
    bash -c '[ "$1" = 1 ] || [ "$1" = 3 ]' _ "$ctl_rc"
  sleep 1
  check "one second later still all at zero and killed" zero_and_killed

  # (b) One version up, both packages: caracara-sim's restart takes caracarad with it
  # (Requires=), the new simulator's wire starts empty.
  arm
  check "upgrade to the next version: all eight thrusters driven before it" drive_all
  pid=$(pid_of caracarad)
  sim_pid=$(pid_of caracara-sim)
  v0=$(dpkg-query -W -f='${Version}' caracarad)
  rc=0
  (cd "$NEXT" && apt_get install ./caracarad_*.deb ./caracara-sim_*.deb) || rc=$?
  check "apt-get install of version $(cd "$NEXT" && echo caracarad_*.deb | cut -d_ -f2) over $v0 while the thrusters run (exit $rc)" \
    bash -c '[ "$1" = 0 ] && dpkg-query -W -f="\${Version}\n" caracarad caracara-sim | grep -c "+systest1$" | grep -qx 2' _ "$rc"
  check "both services restarted (caracarad pid $pid -> $(pid_of caracarad), caracara-sim $sim_pid -> $(pid_of caracara-sim))" \
    bash -c 'systemctl is-active -q caracarad caracara-sim && [ "$(systemctl show -p MainPID --value caracarad)" != "$1" ] &&
             [ "$(systemctl show -p MainPID --value caracara-sim)" != "$2" ]' _ "$pid" "$sim_pid"
  check "the new daemon zeroed every thruster of the new simulator" every_thruster_zeroed_since 0
  check "and nothing but zero orders reached the new simulator" no_order_but_zero_since 0
  check "after the upgrade every thruster is at zero ($(speeds))" all_zero
  check "the upgraded daemon is killed (kill source start)" killed_by_start
  reap_ctl
  info "caracaractl ended with status $ctl_rc: $(tail -n 1 "$out/caracaractl.log")"
  check "caracaractl's commands were refused after the upgrade (status 1 or 3)" \
    bash -c '[ "$1" = 1 ] || [ "$1" = 3 ]' _ "$ctl_rc"
}

debs_purge() {
  local rc=0 left
  (cd / && apt_get purge caracara-sim caracarad) || rc=$?
  check "apt-get purge caracara-sim caracarad (exit $rc)" [ "$rc" = 0 ]
  check "dpkg knows neither package any more" \
    bash -c '! dpkg -s caracarad >/dev/null 2>&1 && ! dpkg -s caracara-sim >/dev/null 2>&1'
  # (Paths as dpkg knows them, /lib/... too: compared by where they lead in this merged-/usr root.)
  left=$(while read -r f; do
           [ "$f" != /. ] && [ -e "$f" ] && ! grep -qxF "$(readlink -f "$f")" /root/fs-before.txt && echo "$f"
         done </root/debs-files.txt)
  [ -z "$left" ] || echo "$left" | sed 's/^/  left by the packages: /'
  check "every file and directory the packages added is gone" [ -z "$left" ]
  # Besides their own files: enablement links, deb-systemd-helper's state, anything a
  # maintainer script made. The caracara user stays (Debian does not remove system users at
  # purge: files may still belong to them), and so do /etc/passwd- and friends (the user
  # database's backups of that change) and the configuration written by hand for check 11.
  left=$(comm -13 /root/fs-before.txt <(fs_list) |
         grep -vxE '/etc/(passwd|group|shadow|gshadow|subuid|subgid)-?|/etc/caracara(/caracarad\.toml)?' || true)
  [ -z "$left" ] || echo "$left" | sed 's/^/  new since the install: /'
  check "nothing else is left on the file system" [ -z "$left" ]
  check "no unit left (caracarad, caracara-sim: not-found)" \
    bash -c '[ "$(systemctl show -p LoadState --value caracarad)" = not-found ] &&
             [ "$(systemctl show -p LoadState --value caracara-sim)" = not-found ]'
  check "no process of the caracara user, no $V or $S on the bus" \
    bash -c '! pgrep -u caracara >/dev/null && ! busctl status "$1" >/dev/null 2>&1 && ! busctl status "$2" >/dev/null 2>&1' _ $V $S
  check "the caracara user and group stay (Debian policy for system users)" \
    bash -c 'getent passwd caracara >/dev/null && getent group caracara >/dev/null'
  check "$CONF, written by hand, stays" [ -f "$CONF" ]
}
