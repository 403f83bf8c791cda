#!/bin/sh
# Make the certificates of a secured zenav deployment with openssl:
#   deploy/secure/make-certs.sh OUT_DIR [ROUTER_HOST_OR_IP ...]
# OUT_DIR gets ca.pem (the deployment's certificate authority; ca.key is its private key:
# keep it off the robot) and one NAME.pem / NAME.key pair per party. The common name (CN)
# of each certificate is the party's name: the router's access control names its
# subjects by it (router, simulator, laser_driver, motor_bridge, perception, tracking,
# planner, monitor, run). The router's certificate also carries ROUTER_HOST_OR_IP (and
# localhost, 127.0.0.1) as subject alternative names, which clients check.
set -eu
out=${1:?usage: make-certs.sh OUT_DIR [ROUTER_HOST_OR_IP ...]}
shift
days=${ZENAV_CERT_DAYS:-825}
mkdir -p "$out"
umask 077
if [ ! -f "$out/ca.pem" ]; then
  openssl req -x509 -newkey rsa:2048 -nodes -days "$days" -subj "/CN=zenav-ca" \
    -keyout "$out/ca.key" -out "$out/ca.pem" \
    -addext "basicConstraints=critical,CA:TRUE" -addext "keyUsage=critical,keyCertSign,cRLSign" \
    2>/dev/null
fi
san="DNS:localhost,IP:127.0.0.1"
for host in "$@"; do
  case $host in
    *[!0-9.]*) san="$san,DNS:$host" ;;
    *) san="$san,IP:$host" ;;
  esac
done
for name in router simulator laser_driver motor_bridge perception tracking planner monitor run; do
  [ -f "$out/$name.pem" ] && continue
  openssl req -newkey rsa:2048 -nodes -subj "/CN=$name" -keyout "$out/$name.key" \
    -out "$out/$name.csr" 2>/dev/null
  ext="$out/$name.ext"
  {
    echo "basicConstraints=CA:FALSE"
    echo "keyUsage=digitalSignature,keyEncipherment"
    echo "extendedKeyUsage=serverAuth,clientAuth"
    echo "subjectAltName=$san"
  } > "$ext"
  openssl x509 -req -in "$out/$name.csr" -CA "$out/ca.pem" -CAkey "$out/ca.key" \
    -CAcreateserial -days "$days" -extfile "$ext" -out "$out/$name.pem" 2>/dev/null
  rm -f "$out/$name.csr" "$ext"
done
rm -f "$out/ca.srl"
chmod 644 "$out"/*.pem
echo "certificates in $out: ca.pem and $(ls "$out" | grep -c '\.pem$') certificates"
