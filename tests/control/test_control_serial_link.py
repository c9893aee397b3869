from __future__ import annotations

import asyncio

import pytest

from aiorobot.control import (
    EncoderTicks,
    FirmwareHeartbeat,
    HostHeartbeat,
    LinkState,
    PtyFirmware,
    SerialLink,
    SetWheelVelocities,
    SimulatedFirmware,
    VersionRequest,
    VersionResponse,
)
from _helpers import wait_until  # noqa: E402




async def test_link_exchanges_packets_with_pty_firmware(tmp_path):
    received = []
    async with PtyFirmware(SimulatedFirmware(wheel_count=2), link_path=str(tmp_path / "tty")) as fw:
        link = SerialLink(fw.port_path, 115200, on_message=received.append)
        assert link.open()
        try:
            link.send(HostHeartbeat(0))
            link.send(VersionRequest())
            link.send(SetWheelVelocities((4.0, 2.0)))
            await wait_until(lambda: any(isinstance(m, VersionResponse) for m in received))
            # the wheels turn in the firmware and their ticks come back
            await wait_until(
                lambda: any(isinstance(m, EncoderTicks) and m.ticks[0] > 100 and m.ticks[1] > 50 for m in received)
            )
            assert fw.firmware.target_rad_s.tolist() == [4.0, 2.0]
            assert any(isinstance(m, FirmwareHeartbeat) for m in received)
            stats = link.statistics()
            assert stats.packets_sent == 3 and stats.decoder.bad_frames == 0
            assert stats.decoder.frames_ok == len(received)
        finally:
            link.close()
    assert link.state is LinkState.CLOSED


async def test_link_notices_port_loss_and_reopens_when_it_returns(tmp_path):
    path = str(tmp_path / "ttyROBOT")
    lost = asyncio.Event()
    received = []
    link = SerialLink(path, 115200, on_message=received.append, on_disconnect=lambda exc: lost.set())
    assert not link.open()  # nothing there yet
    first = PtyFirmware(SimulatedFirmware(wheel_count=2), link_path=path)
    await first.start()
    try:
        assert link.open()
        await wait_until(lambda: len(received) > 3)
        await first.close()  # unplug
        await asyncio.wait_for(lost.wait(), 10.0)
        assert link.state is LinkState.DISCONNECTED
        assert not link.open()
        received.clear()
        async with PtyFirmware(SimulatedFirmware(wheel_count=2), link_path=path) as second:  # plug back in
            assert link.open()
            link.send(HostHeartbeat(1))
            await wait_until(lambda: any(isinstance(m, EncoderTicks) for m in received))
            await wait_until(lambda: not second.firmware.host_timeout)
            stats = link.statistics()
            assert (stats.connects, stats.disconnects) == (2, 1)
    finally:
        await first.close()
        link.close()


async def test_link_over_loop_url_reads_back_its_own_frames():
    received = []
    link = SerialLink("loop://", 115200, on_message=received.append)
    assert link.open()
    try:
        link.send(SetWheelVelocities((1.0, -1.0)))
        link.send(HostHeartbeat(7))
        link.poll()
        assert received == [SetWheelVelocities((1.0, -1.0)), HostHeartbeat(7)]
    finally:
        link.close()


def test_sending_on_a_closed_link_is_refused():
    link = SerialLink("loop://", 115200, on_message=lambda m: None)
    assert link.send(HostHeartbeat(0)) is False
    link.close()
    with pytest.raises(RuntimeError, match=r"is closed; make a new SerialLink$"):
        asyncio.run(_open(link))


async def _open(link):
    return link.open()


async def test_writes_never_block_when_the_other_end_stops_reading():
    import os
    import tty

    master, slave = os.openpty()
    tty.setraw(slave)
    try:
        link = SerialLink(os.ttyname(slave), 115200, on_message=lambda m: None)
        assert link.open()
        try:
            # nobody reads the master side: the pty buffer fills; a blocking write would hang here
            for i in range(20_000):
                link.send(SetWheelVelocities((float(i),) * 4))
            stats = link.statistics()
            assert stats.packets_sent == 20_000
            assert stats.bytes_dropped > 0 and stats.bytes_sent > 0
            assert link.connected
            # the loop stays responsive
            await asyncio.sleep(0)
        finally:
            link.close()
    finally:
        os.close(master)
        os.close(slave)
