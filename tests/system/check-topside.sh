# The vehicle's half of the topside checks (issue: caracaractl -H over SSH), sourced by check.sh,
# whose helpers it uses. The container's sshd is the only thing on the network; topside.sh runs
# outside the container, in the network namespace at the other end of the tether (run.sh), and
# appends its own PASS/FAIL lines to results.txt while this side waits.
TOPSIDE=$out/topside
topside_checks() {
  local u
  # Users that log in over SSH: skipper commands (group caracara), visitor only reads.
  useradd --create-home --shell /bin/bash --groups caracara skipper
  useradd --create-home --shell /bin/bash visitor
  for u in skipper visitor root; do
    install -d -m 0700 -o "$u" -g "$u" "$(getent passwd "$u" | cut -d: -f6)/.ssh"
    install -m 0600 -o "$u" -g "$u" "$TOPSIDE/id_ed25519.pub" "$(getent passwd "$u" | cut -d: -f6)/.ssh/authorized_keys"
  done
  # The vehicle's sshd as docs/topside.md sets it up: keys only, and a dead tether ends the
  # session (and its bridge) within about 6 s.
  mkdir -p /etc/ssh/sshd_config.d
  printf '%s\n' 'PasswordAuthentication no' 'KbdInteractiveAuthentication no' 'ClientAliveInterval 2' \
    'ClientAliveCountMax 3' >/etc/ssh/sshd_config.d/caracara.conf
  systemctl restart ssh
  check "sshd runs in the container (ssh.service active)" wait_until 10 active ssh
  check "sshd -t accepts the configuration" sshd -t
  # Nothing but sshd listens: every TCP socket in LISTEN state is on port 22, and no UDP socket is bound.
  listening() {
    local f proto sl local_addr rest
    for f in /proc/net/tcp /proc/net/tcp6 /proc/net/udp /proc/net/udp6; do
      [ -r "$f" ] || continue
      proto=${f##*/}; proto=${proto%6}
      while read -r sl local_addr _ st rest; do
        [ "$sl" = sl ] && continue
        # TCP: only sockets in LISTEN (0A); UDP: every bound socket.
        [ "$proto" = tcp ] && [ "$st" != 0A ] && continue
        echo "$proto $((16#${local_addr##*:}))"
      done <"$f"
    done
  }
  info "listening sockets in the vehicle's network namespace: $(listening | sort -u | tr '\n' ' ')"
  check "nothing listens on the network but sshd (TCP port 22 only, no UDP)" \
    bash -c '[ "$(echo "$1" | sort -u | tr "\n" " ")" = "tcp 22 " ]' _ "$(listening)"
  id -u skipper >"$TOPSIDE/skipper.uid"
  # The topside knows the vehicle's host key (as a pilot would after checking its fingerprint).
  echo "vehicle,10.231.0.1 $(cut -d' ' -f1,2 /etc/ssh/ssh_host_ed25519_key.pub)" >"$TOPSIDE/known_hosts"
  arm
  ready() { state_is ready; }
  check "before the topside checks: the vehicle is ready" ready
  touch "$TOPSIDE/ready"
  check "the topside checks (topside.sh, outside the container) finished" wait_until 240 test -e "$TOPSIDE/done"
  # The topside leaves the vehicle killed (its last step is the mission's Kill): arm it again.
  if [ "$(state)" = killed ]; then busctl call $V $VP $V ClearKill; fi
  check "after the topside checks the vehicle is ready again" wait_until 10 state_is ready
  # Leave the file system as found (check-debs.sh compares it before the install and after the purge).
  pkill -u skipper; pkill -u visitor
  userdel --remove skipper 2>/dev/null || userdel --force --remove skipper
  userdel --remove visitor 2>/dev/null || userdel --force --remove visitor
  rm -f /etc/ssh/sshd_config.d/caracara.conf /root/.ssh/authorized_keys
  rmdir /root/.ssh 2>/dev/null
  systemctl restart ssh
}
