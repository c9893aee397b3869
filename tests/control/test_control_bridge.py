"""SerialMotorBridge end to end against the simulated firmware on a real pty (pyserial, no mocks)."""

from __future__ import annotations

import math

import numpy as np
import pytest

try:
    from aiorobot import Node, Runtime
except ImportError:  # the runtime is not exported yet
    pytest.skip("needs aiorobot.Node and aiorobot.Runtime", allow_module_level=True)

from aiorobot.msgs.geometry_msgs import Twist  # noqa: E402
from aiorobot.msgs.nav_msgs import Odometry  # noqa: E402
from aiorobot.msgs.sensor_msgs import JointState  # noqa: E402
from aiorobot.msgs.std_msgs import Bool  # noqa: E402

from aiorobot.control import (  # noqa: E402
    EmergencyStop,
    EstopReason,
    FirmwareStatus,
    LinkState,
    MecanumController,
    PtyFirmware,
    SerialMotorBridge,
    SimulatedFirmware,
    SimulatedFirmwareNode,
)
from _helpers import wait_until  # noqa: E402

JOINTS = ["front_left_wheel_joint", "front_right_wheel_joint", "rear_left_wheel_joint", "rear_right_wheel_joint"]




class Probe(Node):
    def __init__(self, **kw):
        super().__init__("probe", **kw)
        self.cmd_pub = self.create_publisher(Twist, "/cmd_vel", 10)
        self.wheel_pub = self.create_publisher(JointState, "/wheel_commands", 10)
        self.estop_pub = self.create_publisher(Bool, "/estop", 10)
        self.joint_states: list[JointState] = []
        self.odom: list[Odometry] = []
        self.streaming: Twist | None = None
        self.create_subscription(JointState, "/joint_states", self.joint_states.append, 100)
        self.create_subscription(Odometry, "/odom", self.odom.append, 100)
        self.create_timer(0.02, self.tick)

    def tick(self):
        if self.streaming is not None:
            self.cmd_pub.publish(self.streaming)


def bridge_for(path, **overrides):
    parameters = {"port": path, "reconnect_period_sec": 0.05, "joint_names": JOINTS}
    parameters.update(overrides)
    return SerialMotorBridge(parameter_overrides=parameters)


async def test_cmd_vel_drives_the_simulated_firmware_and_odometry_comes_back(tmp_path):
    path = str(tmp_path / "ttyMOTORS")
    async with Runtime() as rt:
        firmware_node = SimulatedFirmwareNode(parameter_overrides={"port_link": path, "ticks_per_revolution": 2048})
        bridge = bridge_for(path)
        controller = MecanumController(
            parameter_overrides={"wheel_radius": 0.05, "half_length": 0.15, "half_width": 0.15, "max_accel_x": 5.0}
        )
        probe = Probe()
        rt.add_node(firmware_node)
        rt.add_node(bridge)
        rt.add_node(controller, executor="priority")
        rt.add_node(probe)
        msg = Twist()
        msg.linear.x = 0.2
        probe.streaming = msg
        await wait_until(lambda: probe.odom and probe.odom[-1].pose.pose.position.x > 0.15)
        # commands went in: every wheel of the firmware turns forward at 0.2 / 0.05 = 4 rad/s
        assert firmware_node.firmware.target_rad_s == pytest.approx([4.0] * 4)
        assert np.all(firmware_node.firmware.ticks > 0)
        # ticks came back as joint states, with the firmware's resolution asked over the wire
        assert bridge.firmware_version is not None and bridge.firmware_version.ticks_per_revolution == 2048
        state = probe.joint_states[-1]
        assert list(state.name) == JOINTS
        assert np.all(np.asarray(state.position) > 0)
        # odometry out: straight ahead
        pose = probe.odom[-1].pose.pose
        assert abs(pose.position.y) < 0.01 and abs(2 * math.atan2(pose.orientation.z, pose.orientation.w)) < 0.02
        stats = bridge.statistics()
        assert stats.decoder.bad_frames == 0 and stats.state is LinkState.CONNECTED


async def test_bridge_reconnects_when_the_port_disappears_and_returns(tmp_path):
    path = str(tmp_path / "ttyMOTORS")
    first = PtyFirmware(SimulatedFirmware(), link_path=path)
    await first.start()
    try:
        async with Runtime() as rt:
            bridge = bridge_for(path)
            probe = Probe()
            rt.add_node(bridge)
            rt.add_node(probe)
            wheels = JointState()
            wheels.name = JOINTS
            wheels.velocity = np.array([3.0, 3.0, 3.0, 3.0])
            await wait_until(lambda: len(probe.joint_states) > 5)
            probe.wheel_pub.publish(wheels)
            await wait_until(lambda: first.firmware.ticks[0] > 300)
            await wait_until(lambda: probe.joint_states[-1].position[0] > 0.5)
            before = float(probe.joint_states[-1].position[0])

            await first.close()  # unplugged
            await wait_until(lambda: bridge.link.state is LinkState.DISCONNECTED)
            count = len(probe.joint_states)

            async with PtyFirmware(SimulatedFirmware(), link_path=path) as second:  # plugged back in
                await wait_until(lambda: bridge.link.connected and len(probe.joint_states) > count + 5)
                probe.wheel_pub.publish(wheels)
                await wait_until(lambda: second.firmware.ticks[0] > 300)
                await wait_until(lambda: probe.joint_states[-1].position[0] > before + 0.5)
                stats = bridge.statistics()
                assert (stats.connects, stats.disconnects) == (2, 1)
                # wheel positions continue across the reconnect instead of restarting at the new counters
                after = [float(s.position[0]) for s in probe.joint_states[count:]]
                assert min(after) >= before - 1e-9
    finally:
        await first.close()


async def test_bridge_sends_estop_when_firmware_heartbeat_is_lost_and_clears_it_when_back(tmp_path):
    path = str(tmp_path / "ttyMOTORS")
    # this firmware sends one heartbeat at boot and then falls silent (but keeps sending ticks)
    firmware = SimulatedFirmware(heartbeat_period_sec=1e6)
    async with PtyFirmware(firmware, link_path=path):
        async with Runtime() as rt:
            bridge = bridge_for(path, firmware_timeout_sec=0.3)
            probe = Probe()
            rt.add_node(bridge)
            rt.add_node(probe)
            await wait_until(lambda: firmware.estop)
            assert EmergencyStop(EstopReason.FIRMWARE_HEARTBEAT_LOST) in firmware.received
            assert bridge.estop_active and not bridge.firmware_alive
            # the heartbeat comes back: the bridge clears its own e-stop
            firmware.heartbeat_period_sec = 0.05
            firmware._next_heartbeat = 0.0
            await wait_until(lambda: not firmware.estop)
            assert bridge.firmware_alive and not bridge.estop_active
            await wait_until(lambda: bridge.firmware_status == FirmwareStatus.OK)  # reported by the next heartbeat


async def test_estop_topic_latches_and_clears_the_firmware(tmp_path):
    path = str(tmp_path / "ttyMOTORS")
    firmware = SimulatedFirmware()
    async with PtyFirmware(firmware, link_path=path):
        async with Runtime() as rt:
            bridge = bridge_for(path)
            probe = Probe()
            rt.add_node(bridge)
            rt.add_node(probe)
            await wait_until(lambda: bridge.firmware_alive)
            probe.estop_pub.publish(Bool(data=True))
            await wait_until(lambda: firmware.estop)
            wheels = JointState()
            wheels.name = JOINTS
            wheels.velocity = np.ones(4)
            probe.wheel_pub.publish(wheels)
            await wait_until(lambda: firmware.commands_received >= 1)
            assert not np.any(firmware.target_rad_s)  # ignored while e-stopped
            probe.estop_pub.publish(Bool(data=False))
            await wait_until(lambda: not firmware.estop)
            probe.wheel_pub.publish(wheels)
            await wait_until(lambda: np.all(firmware.target_rad_s == 1.0))


async def test_bad_frames_are_counted_without_losing_the_link(tmp_path, caplog):
    path = str(tmp_path / "ttyMOTORS")
    async with PtyFirmware(SimulatedFirmware(), link_path=path) as fw:
        async with Runtime() as rt:
            bridge = bridge_for(path)
            probe = Probe()
            rt.add_node(bridge)
            rt.add_node(probe)
            await wait_until(lambda: len(probe.joint_states) > 3)
            import os

            # line noise straight into the wire: a CRC-broken frame, a cut block, an oversize run
            os.write(fw._master, b"\x05\x81\x01\x02\x03\x00" + b"\x09\x01\x00" + b"\x07" * 100 + b"\x00")
            await wait_until(lambda: bridge.statistics().decoder.bad_frames >= 3)
            count = len(probe.joint_states)
            await wait_until(lambda: len(probe.joint_states) > count + 3)  # still flowing
            decoder = bridge.statistics().decoder
            assert decoder.oversize == 1 and decoder.truncated >= 1 and decoder.crc_errors >= 1
            assert bridge.link.connected
            await wait_until(lambda: any("bad frames from" in r.getMessage() for r in caplog.records))


async def test_bridge_stops_the_motors_on_shutdown(tmp_path):
    path = str(tmp_path / "ttyMOTORS")
    firmware = SimulatedFirmware()
    async with PtyFirmware(firmware, link_path=path):
        async with Runtime() as rt:
            bridge = bridge_for(path)
            probe = Probe()
            rt.add_node(bridge)
            rt.add_node(probe)
            await wait_until(lambda: bridge.firmware_alive)
            wheels = JointState()
            wheels.velocity = np.full(4, 2.0)  # unnamed: positional
            probe.wheel_pub.publish(wheels)
            await wait_until(lambda: np.all(firmware.target_rad_s == 2.0))
        await wait_until(lambda: not np.any(firmware.target_rad_s))


async def test_simulated_firmware_node_receives_the_bridge_zero_command_at_shutdown(tmp_path):
    path = str(tmp_path / "ttyMOTORS")
    firmware_node = SimulatedFirmwareNode(parameter_overrides={"port_link": path})
    async with Runtime() as rt:
        bridge = bridge_for(path)
        probe = Probe()
        rt.add_node(firmware_node)
        rt.add_node(bridge)
        rt.add_node(probe)
        await wait_until(lambda: bridge.firmware_alive)
        wheels = JointState()
        wheels.name = JOINTS
        wheels.velocity = np.full(4, 2.5)
        probe.wheel_pub.publish(wheels)
        await wait_until(lambda: np.all(firmware_node.firmware.target_rad_s == 2.5))
    assert not np.any(firmware_node.firmware.target_rad_s)
    assert not (tmp_path / "ttyMOTORS").exists()


async def test_joint_state_stamps_follow_the_firmware_clock(tmp_path):
    path = str(tmp_path / "ttyMOTORS")
    firmware = SimulatedFirmware(ticks_period_sec=0.02)
    async with PtyFirmware(firmware, link_path=path):
        async with Runtime() as rt:
            bridge = bridge_for(path)
            probe = Probe()
            rt.add_node(bridge)
            rt.add_node(probe)
            await wait_until(lambda: len(probe.joint_states) > 20)
            stamps = [s.header.stamp.sec * 10**9 + s.header.stamp.nanosec for s in probe.joint_states[-15:]]
            spacing = np.diff(stamps)
            # differences of firmware microsecond timestamps, not of host receive times (nanoseconds)
            assert np.all(spacing % 1000 == 0) and np.all(spacing > 0)
            assert abs(stamps[-1] - bridge.now().nanoseconds) < 200_000_000
