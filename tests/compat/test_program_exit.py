"""rclpy programs end as they do with rclpy, also over zenoh (issue 26 item 11).

A program that ends without ``rclpy.shutdown()`` used to hang over zenoh: the session's
callback threads are non-daemon, so Python waited for them forever and SIGTERM could not end
it. teleop_twist_keyboard is such a program: it reads keys from a tty in raw mode and leaves
its loop on the Ctrl-C byte (0x03), without shutting rclpy down.
"""

from __future__ import annotations

import os
import pty
import signal
import subprocess
import sys
import termios
import textwrap
import threading
import time
from pathlib import Path

import pytest

from ._run import FIXTURES, ROOT, WAIT_SEC, Program
from .test_mixed_zenoh import router  # noqa: F401 - the zenoh router fixture

# in the style of teleop_twist_keyboard.py: raw tty reads, Ctrl-C byte ends the loop, no shutdown
TELEOP = textwrap.dedent("""
    import sys, termios, tty
    import geometry_msgs.msg
    import rclpy

    def get_key(settings):
        tty.setraw(sys.stdin.fileno())
        key = sys.stdin.read(1)
        termios.tcsetattr(sys.stdin, termios.TCSADRAIN, settings)
        return key

    settings = termios.tcgetattr(sys.stdin)
    rclpy.init()
    node = rclpy.create_node('teleop_keys')
    pub = node.create_publisher(geometry_msgs.msg.Twist, 'cmd_vel', 10)
    try:
        print('reading keys', flush=True)
        while True:
            key = get_key(settings)
            twist = geometry_msgs.msg.Twist()
            if key == 'i':
                twist.linear.x = 0.5
            elif key == '\\x03':
                break
            pub.publish(twist)
            print('key', repr(key), flush=True)
    finally:
        pub.publish(geometry_msgs.msg.Twist())
        termios.tcsetattr(sys.stdin, termios.TCSADRAIN, settings)
        print('loop left', flush=True)
""")

SPINNER_THREAD = textwrap.dedent("""
    import threading
    import rclpy
    from rclpy.executors import ExternalShutdownException

    rclpy.init()
    node = rclpy.create_node('spinner')
    ticks = []
    node.create_timer(0.05, lambda: ticks.append(1) or (len(ticks) == 3 and print('ticking after main', flush=True)))

    def spin():
        try:
            rclpy.spin(node)
        except ExternalShutdownException:  # or spin returns: rclpy ends it either way on shutdown
            pass
        print('spin ended by SIGTERM', flush=True)

    threading.Thread(target=spin).start()
    print('main ends', flush=True)
""")


def _env(endpoint: str) -> dict[str, str]:
    env = dict(os.environ)
    env["ZENOH_CONFIG_OVERRIDE"] = f'connect/endpoints=["{endpoint}"]'
    env["PYTHONPATH"] = os.pathsep.join([str(FIXTURES), str(ROOT), env.get("PYTHONPATH", "")])
    env["PYTHONUNBUFFERED"] = "1"
    return env


def _wait_for_raw_mode(controller: int) -> None:
    """Until the program has put its terminal in raw mode (polled, generous bound)."""
    deadline = time.monotonic() + WAIT_SEC
    while termios.tcgetattr(controller)[3] & termios.ICANON:
        assert time.monotonic() < deadline, "the program never put its terminal in raw mode"
        time.sleep(0.01)


def test_a_teleop_program_leaves_on_the_ctrl_c_byte_and_exits_over_zenoh(router, tmp_path: Path):  # noqa: F811
    script = tmp_path / "teleop_keys.py"
    script.write_text(TELEOP)
    controller, terminal = pty.openpty()
    proc = subprocess.Popen(
        [sys.executable, "-m", "aiorobot.cli", "exec", "--transport", "zenoh", str(script)],
        stdin=terminal, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=_env(router), cwd=tmp_path,
    )
    os.close(terminal)
    lines: list[str] = []
    seen = threading.Condition()

    def read() -> None:
        assert proc.stdout is not None
        with proc.stdout:
            for raw in proc.stdout:
                with seen:
                    lines.append(raw.decode(errors="replace").rstrip())
                    seen.notify_all()

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        with seen:
            assert seen.wait_for(lambda: "reading keys" in lines, WAIT_SEC), lines
        _wait_for_raw_mode(controller)  # tty.setraw flushes what was typed before it
        os.write(controller, b"i")
        with seen:
            assert seen.wait_for(lambda: "key 'i'" in lines, WAIT_SEC), lines
        _wait_for_raw_mode(controller)
        os.write(controller, b"\x03")  # what a terminal in raw mode gives for Ctrl-C: a byte, no signal
        code = proc.wait(WAIT_SEC)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        os.close(controller)
        reader.join(5)
    assert code == 0, lines
    assert "loop left" in lines and not any("Traceback" in line for line in lines), lines


def test_a_spinner_thread_keeps_the_program_until_sigterm_ends_it(router, tmp_path: Path):  # noqa: F811
    script = tmp_path / "spinner_thread.py"
    script.write_text(SPINNER_THREAD)
    program = Program(
        str(script), exec_args=("--transport", "zenoh"),
        extra_env={"ZENOH_CONFIG_OVERRIDE": f'connect/endpoints=["{router}"]'},
    )
    program.wait_for("main ends", "ticking after main")  # as with rclpy: the thread spins on
    program.proc.send_signal(signal.SIGTERM)
    assert program.finish() == 0, program.output
    assert "spin ended by SIGTERM" in program.output
    assert "Traceback" not in program.output, program.output


def test_a_program_ending_without_shutdown_exits_on_every_transport(router, tmp_path: Path):  # noqa: F811
    script = tmp_path / "no_shutdown.py"
    script.write_text(textwrap.dedent("""
        import rclpy
        from std_msgs.msg import String
        rclpy.init()
        node = rclpy.create_node('no_shutdown')
        node.create_subscription(String, 'chatter', print, 10)
        node.create_publisher(String, 'chatter', 10).publish(String(data='hello'))
        rclpy.spin_once(node, timeout_sec=5.0)
        print('main ends', flush=True)
    """))
    for transport in ("zenoh", "local"):
        program = Program(
            str(script), exec_args=("--transport", transport),
            extra_env={"ZENOH_CONFIG_OVERRIDE": f'connect/endpoints=["{router}"]'},
        )
        assert program.finish() == 0, (transport, program.output)
        assert "main ends" in program.output, (transport, program.output)


def test_a_ctrl_c_landing_in_a_weakref_callback_still_reaches_the_program(tmp_path: Path):
    # Python runs the SIGINT handler wherever the main thread is; in a weakref callback (a WeakSet's,
    # during garbage collection) the KeyboardInterrupt would be printed as "Exception ignored" and lost.
    script = tmp_path / "interrupted_in_a_finaliser.py"
    script.write_text(textwrap.dedent("""
        import signal, time, weakref
        import rclpy

        class Thing:
            pass

        rclpy.init()
        thing = Thing()
        ref = weakref.ref(thing, lambda _: signal.raise_signal(signal.SIGINT))
        try:
            del thing  # the callback runs, and the handler with it, inside the callback
            time.sleep(60)
            print('the Ctrl-C was lost', flush=True)
        except KeyboardInterrupt:
            print('interrupted, ok =', rclpy.ok(), flush=True)
    """))
    program = Program(str(script), exec_args=("--transport", "local"))
    assert program.finish() == 0, program.output
    assert "interrupted, ok = False" in program.output, program.output
    assert "Exception ignored" not in program.output and "Traceback" not in program.output, program.output


def _spin_interrupted(script: Path, setup: str, spin: str) -> None:
    """Run ``setup`` (rclpy initialised, a SIGINT arranged), then ``spin``, under ``aiorobot exec``:
    the Ctrl-C must come out of ``spin`` as a KeyboardInterrupt, with the context shut down."""
    script.write_text(textwrap.dedent(setup) + textwrap.dedent(f"""
        try:
            {spin}
            print('the Ctrl-C was lost', flush=True)
        except KeyboardInterrupt:
            print('interrupted, ok =', rclpy.ok(), flush=True)
        rclpy.try_shutdown()
        print('ended', flush=True)
    """))
    program = Program(str(script), exec_args=("--transport", "local"))
    assert program.finish() == 0, program.output
    assert "interrupted, ok = False" in program.output and "ended" in program.output, program.output
    assert "Traceback" not in program.output, program.output


def test_a_ctrl_c_as_a_spin_starts_its_loop_is_raised_by_the_spin(tmp_path: Path):
    # the SIGINT lands inside run_until_complete, after it hooked its done callback to the spin's
    # task and before the loop runs: raised there, that callback later stopped the loop under the
    # context's shutdown ("Event loop stopped before Future completed")
    _spin_interrupted(tmp_path / "interrupted_as_the_spin_starts.py", """
        import asyncio, signal
        import rclpy
        from aiorobot.compat._context import default_context

        rclpy.init()
        node = rclpy.create_node('starting_spin')
        loop = default_context().loop

        class Task(asyncio.Task):
            def add_done_callback(self, fn, **kw):
                super().add_done_callback(fn, **kw)
                if fn.__name__ == '_run_until_complete_cb':
                    signal.raise_signal(signal.SIGINT)  # the handler runs as this call returns

        def task_factory(loop, coro, **kw):
            loop.set_task_factory(None)
            return Task(coro, loop=loop, **kw)

        loop.set_task_factory(task_factory)
    """, "rclpy.spin_once(node, timeout_sec=30.0)")


def test_a_ctrl_c_between_two_passes_of_spin_is_a_keyboard_interrupt(tmp_path: Path):
    # rclpy.spin's loop: the SIGINT lands in spin_once after its check for an earlier Ctrl-C and
    # before its check that the context is up; the handler has shut the context down, and that
    # check raised NotInitializedException ("rclpy.init() has not been called") out of spin
    _spin_interrupted(tmp_path / "interrupted_between_passes.py", """
        import signal
        import rclpy
        from aiorobot.compat._context import default_context

        rclpy.init()
        node = rclpy.create_node('spinning')
        ctx = default_context()
        checked = ctx.raise_if_interrupted

        def then_interrupted():
            checked()
            if ctx.raise_if_interrupted is then_interrupted:
                ctx.raise_if_interrupted = checked
                signal.raise_signal(signal.SIGINT)  # the handler runs as this call returns

        ctx.raise_if_interrupted = then_interrupted
    """, "rclpy.spin(node)")


# sys.exit() in a callback: rclpy's spin raises the SystemExit; the timer lives on for a later spin
EXIT_IN_CALLBACK = textwrap.dedent("""
    import sys
    import rclpy
    from rclpy.executors import MultiThreadedExecutor

    rclpy.init()
    node = rclpy.create_node('quitter')
    ticks = []

    def tick():
        ticks.append(len(ticks) + 1)
        print('tick', ticks[-1], flush=True)
        if len(ticks) == 3:
            sys.exit(3)

    node.create_timer(0.01, tick)
    try:
        rclpy.spin(node)
    except SystemExit as exc:
        print('spin left with SystemExit', exc.code, flush=True)
    while len(ticks) < 5:
        rclpy.spin_once(node, timeout_sec=1.0)
    print('ticks', ticks, flush=True)
    rclpy.shutdown()
    sys.exit(3)
""")


@pytest.mark.parametrize("spin", ["rclpy.spin(node)", "rclpy.spin(node, executor=MultiThreadedExecutor())"])
def test_sys_exit_in_a_callback_leaves_spin_and_the_timer_goes_on(tmp_path: Path, spin: str):
    script = tmp_path / "exit_in_callback.py"
    script.write_text(EXIT_IN_CALLBACK.replace("rclpy.spin(node)", spin))
    program = Program(str(script), exec_args=("--transport", "local"))
    assert program.finish() == 3
    assert "spin left with SystemExit 3" in program.output
    assert "ticks [1, 2, 3, 4, 5]" in program.output
    assert "Traceback" not in program.output and "never retrieved" not in program.output, program.output
