#!/usr/bin/env python3
"""fake_tev.py: a stand-in for the tev viewer on the loopback interface, for
tests/render/test-display.sh. It accepts one connection, decodes every packet of tev's
protocol that core/display_tev.h describes (int32 length, uint8 type, then the fields),
checks each packet's length against its fields, and keeps the latest value of every pixel
of every channel. When the client closes, it writes what it saw to OUT as text:
  create NAME WIDTH HEIGHT CHANNELS...   one line per CreateImage
  updates N                              how many UpdateImage packets came
  pixel NAME CHANNEL X Y VALUE           every pixel's last value (repr of the float)
  error TEXT                             a packet it could not decode (then it stops)
usage: fake_tev.py PORT_FILE OUT [--close-after N]   (PORT_FILE receives the port; with
--close-after it hangs up after N packets, as a viewer that goes away)"""
import socket
import struct
import sys


def read_string(data, at):
    end = data.index(b"\0", at)
    return data[at:end].decode(), end + 1


def main():
    port_file, out_path = sys.argv[1], sys.argv[2]
    close_after = int(sys.argv[4]) if len(sys.argv) > 4 and sys.argv[3] == "--close-after" else None
    server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    server.bind(("127.0.0.1", 0))
    server.listen(1)
    server.settimeout(60)
    with open(port_file, "w") as f:
        f.write("%d\n" % server.getsockname()[1])
    lines, pixels, updates, packets = [], {}, 0, 0
    connection, _ = server.accept()
    connection.settimeout(60)
    buffer = b""
    try:
        while close_after is None or packets < close_after:
            while len(buffer) < 4 or len(buffer) < struct.unpack("<i", buffer[:4])[0]:
                chunk = connection.recv(65536)
                if not chunk:
                    raise EOFError
                buffer += chunk
            length = struct.unpack("<i", buffer[:4])[0]
            packet, buffer = buffer[:length], buffer[length:]
            packets += 1
            kind = packet[4]
            if kind == 4:
                at = 6
                name, at = read_string(packet, at)
                width, height, count = struct.unpack("<iii", packet[at:at + 12])
                at += 12
                channels = []
                for _ in range(count):
                    channel, at = read_string(packet, at)
                    channels.append(channel)
                if at != length:
                    raise ValueError("CreateImage of %d bytes holds %d" % (length, at))
                lines.append("create %s %d %d %s" % (name, width, height, " ".join(channels)))
            elif kind == 3:
                at = 6
                name, at = read_string(packet, at)
                channel, at = read_string(packet, at)
                x, y, width, height = struct.unpack("<iiii", packet[at:at + 16])
                at += 16
                if length - at != 4 * width * height:
                    raise ValueError("UpdateImage %dx%d of %d value bytes" % (width, height, length - at))
                values = struct.unpack("<%df" % (width * height), packet[at:])
                for i, value in enumerate(values):
                    pixels[(name, channel, x + i % width, y + i // width)] = value
                updates += 1
            else:
                raise ValueError("packet type %d" % kind)
    except EOFError:
        pass
    except ValueError as e:
        lines.append("error %s" % e)
    connection.close()
    with open(out_path, "w") as f:
        for line in lines:
            f.write(line + "\n")
        f.write("updates %d\n" % updates)
        for (name, channel, x, y), value in sorted(pixels.items()):
            f.write("pixel %s %s %d %d %r\n" % (name, channel, x, y, value))


main()
