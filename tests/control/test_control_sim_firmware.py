from __future__ import annotations

import asyncio
import math

import numpy as np
import pytest
import serial

from aiorobot.control import (
    ClearEmergencyStop,
    EmergencyStop,
    EncoderTicks,
    FirmwareHeartbeat,
    FirmwareStatus,
    HostHeartbeat,
    PtyFirmware,
    SetWheelVelocities,
    SimulatedFirmware,
    StreamDecoder,
    VersionRequest,
    VersionResponse,
    encode_message,
)


def frames(*messages):
    return b"".join(encode_message(m, i) for i, m in enumerate(messages))


def test_motor_model_is_first_order_and_integrates_angle_exactly():
    fw = SimulatedFirmware(wheel_count=2, motor_time_constant_sec=0.1)
    fw.receive(frames(HostHeartbeat(0), SetWheelVelocities((10.0, -5.0))), 0.0)
    fw.advance(0.1)  # one time constant
    assert fw.speed_rad_s == pytest.approx([10.0 * (1 - math.exp(-1)), -5.0 * (1 - math.exp(-1))])
    # angle of a first-order step response: target * (t - tau * (1 - exp(-t/tau)))
    assert fw.angle_rad[0] == pytest.approx(10.0 * (0.1 - 0.1 * (1 - math.exp(-1))))


def test_commands_are_ignored_until_the_host_heartbeat_arrives():
    fw = SimulatedFirmware(wheel_count=2)
    fw.receive(frames(SetWheelVelocities((5.0, 5.0))), 0.0)
    assert fw.status & FirmwareStatus.HOST_TIMEOUT
    assert fw.target_rad_s.tolist() == [0.0, 0.0]


def test_host_heartbeat_loss_holds_the_motors():
    fw = SimulatedFirmware(wheel_count=2, host_timeout_sec=0.5)
    fw.receive(frames(HostHeartbeat(0), SetWheelVelocities((5.0, 5.0))), 0.0)
    fw.advance(0.4)
    assert fw.target_rad_s.tolist() == [5.0, 5.0]
    fw.advance(0.6)
    assert fw.target_rad_s.tolist() == [0.0, 0.0]
    assert fw.status == FirmwareStatus.HOST_TIMEOUT


def test_emergency_stop_latches_until_cleared():
    fw = SimulatedFirmware(wheel_count=2)
    fw.receive(frames(HostHeartbeat(0), SetWheelVelocities((5.0, 5.0)), EmergencyStop(0)), 0.0)
    assert fw.target_rad_s.tolist() == [0.0, 0.0] and fw.status == FirmwareStatus.ESTOP
    fw.receive(frames(SetWheelVelocities((5.0, 5.0))), 0.1)
    assert fw.target_rad_s.tolist() == [0.0, 0.0]
    fw.receive(frames(ClearEmergencyStop(), HostHeartbeat(1)), 0.2)
    assert fw.target_rad_s.tolist() == [0.0, 0.0]  # cleared, but still zero until the next command
    fw.receive(frames(SetWheelVelocities((2.0, 1.0))), 0.3)
    assert fw.target_rad_s.tolist() == [2.0, 1.0]


def test_firmware_over_pyserial_loop_url_answers_version_and_streams_ticks():
    port = serial.serial_for_url("loop://", timeout=0)
    try:
        fw = SimulatedFirmware(wheel_count=4, ticks_per_revolution=1000, motor_time_constant_sec=0.01)
        host = StreamDecoder()
        port.write(frames(HostHeartbeat(0), VersionRequest(), SetWheelVelocities((2 * math.pi,) * 4)))
        received = []
        for step in range(101):
            if step % 10 == 0:
                port.write(encode_message(HostHeartbeat(step * 10), 10 + step))
            fw.service(port, step * 0.01)
            received += host.feed(port.read(port.in_waiting))
        version = [m for m in received if isinstance(m, VersionResponse)]
        assert version == [VersionResponse(1, 0, 1, 0, 4, 1000, "aiorobot-sim")]
        ticks = [m for m in received if isinstance(m, EncoderTicks)]
        assert len(ticks) >= 40
        # one revolution per second, minus the first-order lag, at the latch time of the counters
        t = ticks[-1].timestamp_us * 1e-6
        assert t >= 0.95
        expected = 1000 * (t - 0.01 * (1 - math.exp(-t / 0.01)))
        assert ticks[-1].ticks == (math.floor(expected),) * 4
        assert any(isinstance(m, FirmwareHeartbeat) for m in received)
        assert host.statistics().bad_frames == 0
    finally:
        port.close()


async def test_pty_firmware_talks_to_pyserial_on_the_slave_device(tmp_path):
    link = str(tmp_path / "ttyROBOT")
    async with PtyFirmware(SimulatedFirmware(wheel_count=2), link_path=link) as fw:
        port = serial.Serial(fw.port_path, 115200, timeout=0)
        try:
            port.write(frames(HostHeartbeat(0), SetWheelVelocities((3.0, -3.0)), VersionRequest()))
            decoder = StreamDecoder()
            got: list = []
            loop = asyncio.get_running_loop()
            arrived = asyncio.Event()

            def on_readable():
                got.extend(decoder.feed(port.read(port.in_waiting or 1)))
                ticks = [m for m in got if isinstance(m, EncoderTicks)]
                if any(isinstance(m, VersionResponse) for m in got) and ticks and ticks[-1].ticks[0] > 100:
                    arrived.set()

            loop.add_reader(port.fileno(), on_readable)
            try:
                await asyncio.wait_for(arrived.wait(), 10.0)
            finally:
                loop.remove_reader(port.fileno())
            last = [m for m in got if isinstance(m, EncoderTicks)][-1]
            assert last.ticks[0] > 100 and last.ticks[1] < -100
            assert np.sign(fw.firmware.speed_rad_s).tolist() == [1.0, -1.0]
        finally:
            port.close()
    assert not (tmp_path / "ttyROBOT").exists()


async def test_pty_firmware_refuses_to_replace_a_file_that_is_not_its_link(tmp_path):
    precious = tmp_path / "ttyUSB0"
    precious.write_text("not a link")
    with pytest.raises(FileExistsError, match=r"exists and is not a symlink; PtyFirmware only replaces its own links"):
        await PtyFirmware(link_path=str(precious)).start()
    assert precious.read_text() == "not a link"
