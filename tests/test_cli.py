"""The ``aiorobot`` command line, end to end in subprocesses, and its argument handling."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import sysconfig
import textwrap
from pathlib import Path

import pytest

from aiorobot.cli import COMMANDS, main

CONFIGS = Path(__file__).parent / "configs"
BAD_CONFIGS = sorted((CONFIGS / "bad").glob("*.toml")) + sorted((CONFIGS / "build").glob("*.toml"))
#: the small example graph (an IMU publisher and a monitor on the priority loop); ``aiorobot run`` alone runs the demo
EXAMPLE_GRAPH = Path(__file__).resolve().parent.parent / "aiorobot" / "examples" / "default.toml"
RUN_TIMEOUT_SEC = 120.0  # generous: a shared 2-core machine may stall for seconds
SCRIPT = Path(sysconfig.get_path("scripts")) / "aiorobot"
NOISE = ("Traceback", "Task was destroyed", "Warning", "never awaited", "Exception ignored")


def aiorobot(*args: str, cwd: Path | None = None, timeout: float = RUN_TIMEOUT_SEC) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "aiorobot.cli", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=cwd,
        env=_env(),
    )


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env.pop("PYTHONWARNINGS", None)
    return env


def expected_message(path: Path) -> str:
    first = path.read_text(encoding="utf-8").splitlines()[0]
    text = first.removeprefix("# expect: ").replace("{dir}", str(path.parent.resolve()))
    return f"{path}: {text}"


def assert_clean(stderr: str) -> None:
    for noise in NOISE:
        assert noise not in stderr, f"{noise!r} on stderr:\n{stderr}"


@pytest.mark.parametrize("path", BAD_CONFIGS, ids=lambda p: f"{p.parent.name}-{p.stem}")
def test_run_bad_config_prints_one_line_and_exits_2_without_starting(path: Path) -> None:
    result = aiorobot("run", str(path))
    assert result.returncode == 2, result.stderr
    assert result.stderr.splitlines() == [expected_message(path)]
    assert result.stdout == "", "no status line: nothing started"


def test_run_missing_file_prints_one_line_and_exits_2(tmp_path: Path) -> None:
    missing = tmp_path / "missing.toml"
    result = aiorobot("run", str(missing))
    assert result.returncode == 2
    assert result.stderr.splitlines() == [f"{missing}: cannot read the file: No such file or directory"]


def test_duration_that_is_not_a_number_exits_2_with_one_line() -> None:
    result = aiorobot("run", "--duration", "soon")
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        "aiorobot run: error: argument --duration: expected a number of seconds such as 3 or 0.5, "
        "found 'soon' (see 'aiorobot run --help')"
    ]
    assert result.stdout == ""


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (
            ["run", "--duration", "-1"],
            "aiorobot run: error: argument --duration: expected a positive number of seconds, found '-1' "
            "(see 'aiorobot run --help')",
        ),
        (
            ["run", "--duration", "nan"],
            "aiorobot run: error: argument --duration: expected a positive number of seconds, found 'nan' "
            "(see 'aiorobot run --help')",
        ),
        (
            ["run", "a.toml", "b.toml"],
            "aiorobot: error: unrecognized arguments: b.toml (see 'aiorobot --help')",
        ),
        (["run", "--fast"], "aiorobot: error: unrecognized arguments: --fast (see 'aiorobot --help')"),
        ([], f"aiorobot: error: expected a command ({', '.join(COMMANDS)}), found none (see 'aiorobot --help')"),
        (
            ["fly"],
            f"aiorobot: error: argument COMMAND: invalid choice: 'fly' (choose from {', '.join(map(repr, COMMANDS))}) "
            "(see 'aiorobot --help')",
        ),
    ],
)
def test_bad_arguments_give_one_line_and_status_2(
    argv: list[str], expected: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.err.splitlines() == [expected]
    assert captured.out == ""


def test_every_command_has_help(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--help"]) == 0
    top = capsys.readouterr().out
    for name in COMMANDS:
        assert name in top
    # what `aiorobot run` with no file does: the demo, not "the bundled example" it once said
    assert "with no file, the demo" in " ".join(top.split()) and "bundled example" not in top
    assert main(["run", "--help"]) == 0
    run_help = capsys.readouterr().out
    assert "usage: aiorobot run" in run_help and "--duration SEC" in run_help


def test_missing_command_module_is_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setitem(COMMANDS, "ghost", ("aiorobot.ghost._cli", "not installed here"))
    assert main(["ghost"]) == 2
    assert capsys.readouterr().err.splitlines() == [
        "aiorobot: error: the 'ghost' command is not available in this installation "
        "(aiorobot.ghost._cli is missing)"
    ]


def test_help_does_not_import_heavy_modules() -> None:
    """``--help`` loads nothing heavy beyond what ``import aiorobot`` itself loads."""
    code = (
        "import sys, contextlib, io\n"
        "heavy = {'numpy', 'numba', 'rosbags', 'cv2', 'rich', 'uvloop', 'filterpy', 'scipy'}\n"
        "import aiorobot\n"
        "before = {m.split('.')[0] for m in sys.modules}\n"
        "from aiorobot.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        "    main(['--help']); main(['run', '--help'])\n"
        "after = {m.split('.')[0] for m in sys.modules}\n"
        "print(sorted((after - before) & heavy), sorted(after & {'numba', 'rosbags', 'cv2'}))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert result.stdout.strip() == "[] []", result.stderr


def test_console_script_runs_the_cli() -> None:
    if not SCRIPT.exists():
        pytest.skip(f"the package is not installed with its console script ({SCRIPT})")
    result = subprocess.run([str(SCRIPT), "--help"], capture_output=True, text=True, timeout=60)
    assert result.returncode == 0 and "usage: aiorobot" in result.stdout


@pytest.mark.timeout(RUN_TIMEOUT_SEC + 60)
def test_bundled_example_runs_for_duration_and_exits_0() -> None:
    result = aiorobot("run", str(EXAMPLE_GRAPH), "--duration", "3")
    assert result.returncode == 0, result.stderr
    assert_clean(result.stderr)
    lines = result.stdout.splitlines()
    assert any(line.startswith("[") and "imu_monitor" in line for line in lines), result.stdout
    summary = [line for line in lines if line.startswith("imu_monitor: received")]
    assert len(summary) == 1, result.stdout
    received = int(summary[0].split()[2])
    assert received > 0, "messages crossed from the main loop to the priority loop"


USER_NODES = textwrap.dedent(
    '''
    from aiorobot import Node
    from aiorobot.msgs.std_msgs import String


    class Greeter(Node):
        def __init__(self, **kw):
            super().__init__("greeter", **kw)
            self.greeting = self.declare_parameter("greeting", "hello").value
            self.pub = self.create_publisher(String, "greetings", 10)
            self.create_timer(0.05, self.tick)
            self.sent = 0

        async def tick(self):
            self.pub.publish(String(data=self.greeting))
            self.sent += 1

        def status_line(self):
            return f"{self.get_fully_qualified_name()} says {self.greeting!r}"

        def summary(self):
            return f"greeter sent {'some' if self.sent else 'no'} greetings"
    '''
)


@pytest.mark.timeout(RUN_TIMEOUT_SEC + 60)
def test_user_module_is_loaded_from_the_config_folder(tmp_path: Path) -> None:
    graph = tmp_path / "robot"
    graph.mkdir()
    (graph / "my_nodes.py").write_text(USER_NODES, encoding="utf-8")
    (graph / "config.toml").write_text(
        '[[nodes]]\nuse = "my_nodes:Greeter"\nnamespace = "/lab"\nparameters = { greeting = "hi" }\n',
        encoding="utf-8",
    )
    elsewhere = tmp_path / "cwd"
    elsewhere.mkdir()
    result = aiorobot("run", str(graph / "config.toml"), "--duration", "1.5", cwd=elsewhere)
    assert result.returncode == 0, result.stderr
    assert_clean(result.stderr)
    assert "/lab/greeter says 'hi'" in result.stdout
    assert "greeter sent some greetings" in result.stdout.splitlines()


@pytest.mark.timeout(RUN_TIMEOUT_SEC + 60)
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_signal_stops_a_running_graph_cleanly(signum: signal.Signals) -> None:
    proc = subprocess.Popen(
        [sys.executable, "-m", "aiorobot.cli", "run", str(EXAMPLE_GRAPH)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_env(),
    )
    try:
        assert proc.stdout is not None
        first = proc.stdout.readline()  # blocks until the first status line: the graph runs
        assert first.startswith("[") and "imu_monitor" in first, first
        proc.send_signal(signum)
        rest, stderr = proc.communicate(timeout=RUN_TIMEOUT_SEC)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == 0, stderr
    assert_clean(stderr)
    assert "imu_monitor: received" in rest


QOS_NODES = textwrap.dedent(
    '''
    from aiorobot import Node, QoSProfile, ReliabilityPolicy
    from aiorobot.msgs.std_msgs import String


    class BestEffortTalker(Node):
        def __init__(self, **kw):
            super().__init__("talker", **kw)
            self.create_publisher(String, "chatter", QoSProfile(reliability=ReliabilityPolicy.BEST_EFFORT))


    class ReliableListener(Node):
        def __init__(self, **kw):
            super().__init__("listener", **kw)
            self.create_subscription(String, "chatter", print, 10)
    '''
)


def test_strict_qos_mismatch_in_config_graph_is_a_one_line_config_error(tmp_path: Path) -> None:
    (tmp_path / "qos_nodes.py").write_text(QOS_NODES, encoding="utf-8")
    config = tmp_path / "strict.toml"
    config.write_text(
        '[runtime]\nstrict_qos = true\n[[nodes]]\nuse = "qos_nodes:BestEffortTalker"\n'
        '[[nodes]]\nuse = "qos_nodes:ReliableListener"\n',
        encoding="utf-8",
    )
    result = aiorobot("run", str(config), "--duration", "30")
    assert result.returncode == 2
    (line,) = result.stderr.splitlines()
    assert line.startswith(f"{config}: nodes[1]: runtime.strict_qos is set and incompatible QoS on /chatter: ")
    assert "/talker" in line and "/listener" in line
    assert result.stdout == "", "spin never started"


LOGGING_NODES = textwrap.dedent(
    '''
    from aiorobot import Node


    class Chatty(Node):
        def __init__(self, **kw):
            super().__init__("chatty", **kw)
            self.create_timer(0.05, self.tick)

        async def tick(self):
            self.get_logger().debug("chatty debug line", once=True)
            self.get_logger().info("chatty info line", once=True)


    class Quiet(Chatty):
        def __init__(self, **kw):
            super().__init__(**kw)

        async def tick(self):
            self.get_logger().info("quiet info line", once=True)
            self.get_logger().warning("quiet warning line", once=True)
    '''
)


def test_log_levels_from_config_apply_runtime_wide_and_per_node(tmp_path: Path) -> None:
    (tmp_path / "log_nodes.py").write_text(LOGGING_NODES, encoding="utf-8")
    config = tmp_path / "logs.toml"
    config.write_text(
        '[runtime]\nlog_level = "warning"\n'
        '[[nodes]]\nuse = "log_nodes:Chatty"\nlog_level = "debug"\n'
        '[[nodes]]\nname = "quiet"\nuse = "log_nodes:Quiet"\n',
        encoding="utf-8",
    )
    result = aiorobot("run", str(config), "--duration", "1.5")
    assert result.returncode == 0, result.stderr
    assert "[DEBUG]" in result.stderr and "[/chatty]: chatty debug line" in result.stderr
    assert "[/chatty]: chatty info line" in result.stderr
    assert "[/quiet]: quiet warning line" in result.stderr
    assert "quiet info line" not in result.stderr, "the runtime-wide level is warning"


@pytest.mark.timeout(RUN_TIMEOUT_SEC + 60)
def test_closed_stdout_pipe_stops_the_run_quietly() -> None:
    proc = subprocess.Popen(
        [sys.executable, "-m", "aiorobot.cli", "run", str(EXAMPLE_GRAPH)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_env(),
    )
    try:
        assert proc.stdout is not None and proc.stderr is not None
        assert proc.stdout.readline().startswith("[")  # as `aiorobot run | head -1`
        proc.stdout.close()
        stderr = proc.stderr.read()
        proc.wait(timeout=RUN_TIMEOUT_SEC)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        proc.stderr.close()
    assert proc.returncode == 0, stderr
    assert_clean(stderr)


@pytest.mark.timeout(RUN_TIMEOUT_SEC + 60)
def test_on_a_terminal_the_status_is_a_live_display_and_exits_cleanly() -> None:
    leader, follower = os.openpty()
    env = _env() | {"COLUMNS": "200", "TERM": "xterm"}
    with subprocess.Popen(
        [sys.executable, "-m", "aiorobot.cli", "run", str(EXAMPLE_GRAPH), "--duration", "2", "--status-period", "0.5"],
        stdin=subprocess.DEVNULL,
        stdout=follower,
        stderr=follower,
        env=env,
    ) as proc:
        os.close(follower)
        chunks = []
        while True:
            try:
                chunk = os.read(leader, 65536)
            except OSError:  # EIO: every writer has closed the terminal
                break
            if not chunk:
                break
            chunks.append(chunk)
        os.close(leader)
        returncode = proc.wait(timeout=RUN_TIMEOUT_SEC)
    output = b"".join(chunks).decode("utf-8", "replace")
    assert returncode == 0, output
    assert_clean(output)
    assert "\x1b[?25l" in output, "rich hides the cursor while the Live display runs"
    assert "imu_monitor: received" in output


def test_ctrl_c_while_a_command_starts_is_one_line_and_status_130(monkeypatch, capsys) -> None:
    """Ctrl-C during the first fraction of a second (imports, start-up): no traceback."""
    import importlib

    from aiorobot import cli

    def interrupted(name: str):  # the KeyboardInterrupt a Ctrl-C raises inside an import
        raise KeyboardInterrupt

    monkeypatch.setattr(importlib, "import_module", interrupted)
    assert cli.main(["run"]) == 130
    assert capsys.readouterr().err == "aiorobot: interrupted\n"
