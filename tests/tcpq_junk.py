#!/usr/bin/python3
"""A foreign publisher on LCM's tcpq hub (lcm.lcm.TCPService), speaking the
hub's protocol (LCM 1.3.1, lcm/lcm_tcpq.c): 8 bytes of junk on CHANNEL every
PERIOD seconds until killed. Every subscriber of CHANNEL receives them, so
a process that exits has bytes unread.

Usage: tcpq_junk.py PORT CHANNEL PERIOD
"""
import socket
import struct
import sys
import time

if len(sys.argv) != 4:
    print(__doc__, file=sys.stderr)
    sys.exit(0 if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help") else 2)
port, channel, period = int(sys.argv[1]), sys.argv[2].encode(), float(sys.argv[3])
s = socket.create_connection(("127.0.0.1", port))
s.sendall(struct.pack(">II", 0x287617FB, 0x0100))  # client magic, protocol version
hello = b""
while len(hello) < 8:
    hello += s.recv(8 - len(hello))
if struct.unpack(">I", hello[:4])[0] != 0x287617FA:
    sys.exit("tcpq_junk: not an LCM tcpq hub")
print("tcpq_junk: ready", file=sys.stderr, flush=True)
message = struct.pack(">II", 1, len(channel)) + channel + struct.pack(">I", 8) + b"junkjunk"  # 1: publish
while True:
    s.sendall(message)
    time.sleep(period)
