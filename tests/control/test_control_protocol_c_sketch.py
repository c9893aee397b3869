"""The C sketch in docs/serial-protocol.md compiles and interoperates with the Python implementation."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from aiorobot.control import HostHeartbeat, SetWheelVelocities, StreamDecoder, encode_message

DOC = Path(__file__).resolve().parents[2] / "docs" / "serial-protocol.md"

PRELUDE = r"""
#include <stdio.h>
#define WHEELS 4
static int estop, host_timeout;
static float target[WHEELS];
static unsigned long last_host_heartbeat_ms;
static unsigned long millis(void) { return 0; }
static void stop_all_motors(void) { for (int i = 0; i < WHEELS; i++) target[i] = 0; }
static void send_version(void) {}
static void reset_encoders(void) {}
static int heartbeats;
static void write_bytes(const unsigned char *data, unsigned long n) {
    for (unsigned long i = 0; i < n; i++) printf("%02x", data[i]);
    printf("\n");
}
"""

MAIN = r"""
int main(void) {
    printf("%04x\n", crc16_ccitt_false((const uint8_t *)"123456789", 9));
    float v[2] = {1.0f, -1.0f};
    uint8_t p[9];
    p[0] = 2; memcpy(p + 1, v, 8);
    tx_seq = 7;
    send_packet(0x01, p, 9);
    int c;
    unsigned int byte;
    while (scanf("%2x", &byte) == 1) on_byte((uint8_t)byte);
    printf("%g %g %g %g\n", target[0], target[1], target[2], target[3]);
    return 0;
}
"""


def c_sketch() -> str:
    text = DOC.read_text()
    section = text[text.index("## 9.") :]
    return re.search(r"```c\n(.*?)```", section, re.S).group(1)


@pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler")
def test_c_sketch_compiles_and_matches_python(tmp_path):
    source = tmp_path / "sketch.c"
    code = c_sketch()
    # the sketch calls write_bytes before the prelude could declare it otherwise
    source.write_text("#include <stdint.h>\n#include <string.h>\n" + PRELUDE + code + MAIN)
    binary = tmp_path / "sketch"
    subprocess.run(["cc", "-std=c99", "-Wall", "-Wno-unused-variable", "-Wno-unused-function", "-o", str(binary), str(source)], check=True, capture_output=True)
    stream = (
        b"\x17\x00garbage"  # noise first: the C receiver must resynchronise
        + encode_message(HostHeartbeat(5), 0)
        + encode_message(SetWheelVelocities((0.5, -0.25, 1.5, 2.0)), 1)
    )
    result = subprocess.run([str(binary)], input=stream.hex(), capture_output=True, text=True, check=True)
    crc_line, frame_line, targets_line = result.stdout.split()[:1] + result.stdout.splitlines()[1:3]
    assert crc_line == "29b1"
    assert bytes.fromhex(frame_line) == encode_message(SetWheelVelocities((1.0, -1.0)), 7)
    assert StreamDecoder().feed(bytes.fromhex(frame_line)) == [SetWheelVelocities((1.0, -1.0))]
    assert targets_line.split() == ["0.5", "-0.25", "1.5", "2"]
