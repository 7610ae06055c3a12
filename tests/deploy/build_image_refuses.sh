#!/usr/bin/env bash
# scripts/build_image.sh refuses a bad robot configuration at build time, before it needs root, the
# network or any tool: exit 2 and a message naming the file and the key (issue 24, "bad input").
# usage: build_image_refuses.sh ORTHOFLOW_BINARY
set -uo pipefail
bin=$1
here=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
status=0
# expect NAME TEXT-IN-STDERR YAML: builds with YAML as robot.yaml and checks exit 2 and the message.
expect() {
  local name=$1 text=$2
  printf '%s\n' "$3" > "$tmp/$name.yaml"
  out=$(bash "$here/scripts/build_image.sh" --arch amd64 --out "$tmp/out" --config "$tmp/$name.yaml" \
        --orthoflow "$bin" 2>&1)
  rc=$?
  if [ $rc = 2 ] && printf '%s' "$out" | grep -qF -- "$text"; then
    echo "ok: $name: $(printf '%s' "$out" | head -n 1)"
  else
    echo "FAIL: $name: exit $rc, wanted 2 and '$text' in: $out"
    status=1
  fi
  [ ! -e "$tmp/out/orthoflow-amd64.img" ] || { echo "FAIL: $name: an image was written"; status=1; }
}
expect not_yaml "$tmp/not_yaml.yaml: not YAML" 'hostname: ['
expect unknown_key "wifi: unknown key" 'wifi: true'
expect bad_port "ui.listen" 'ui: {listen: "0.0.0.0:99999"}'
expect bad_host "hostname" 'hostname: "robot; reboot"'
expect missing_graph "is not a file" 'graph: nowhere.yaml'
expect missing_token "ui.token_file" 'ui: {token_file: nowhere.token}'
expect empty "empty" ''
# Files a config names stay inside its folder and are what they claim to be (issue 52, item 1).
expect token_absolute "inside the config's folder" 'ui: {token_file: "/etc/shadow"}'
expect graph_absolute "inside the config's folder" 'graph: /etc/passwd'
expect keys_up "inside the config's folder" 'admin: {ssh_authorized_keys: ../keys}'
ln -s /etc/shadow "$tmp/shadow.token"
expect token_symlink "leads outside the config's folder" 'ui: {token_file: shadow.token}'
cp /etc/passwd "$tmp/passwd.yaml"
expect graph_not_a_graph "graph: passwd.yaml" 'graph: passwd.yaml'
mkfifo "$tmp/fifo.token"
expect token_fifo "is not a regular file" 'ui: {token_file: fifo.token}'
head -c 100000 /dev/urandom | base64 -w 0 > "$tmp/huge.token"
expect token_huge "larger than the limit of 4096 bytes" 'ui: {token_file: huge.token}'
out=$(bash "$here/scripts/build_image.sh" --arch armhf --out "$tmp/out" --orthoflow "$bin" 2>&1)
if [ $? = 2 ] && printf '%s' "$out" | grep -q "amd64 or arm64"; then echo "ok: bad arch"; else echo "FAIL: arch: $out"; status=1; fi
exit $status
