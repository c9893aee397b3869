"""``aiorobot run`` exit status follows failures; node loggers print by default (as rclpy)."""

from __future__ import annotations

import subprocess
import sys
import textwrap

from ._proc import AIOROBOT

NODES = textwrap.dedent(
    '''
    from aiorobot import Node


    class Faulty(Node):
        def __init__(self, **kw):
            super().__init__("faulty", **kw)
            self.fail = self.declare_parameter("fail", "callback").value
            self.ticks = 0
            self.create_timer(0.01, self.tick)

        async def on_start(self):
            if self.fail == "on_start":
                raise RuntimeError("motor driver not found")

        def tick(self):
            self.ticks += 1
            if self.ticks % 10 == 0:
                print(f"tick {self.ticks}", flush=True)
            if self.fail == "callback":
                raise ValueError(f"bad reading {self.ticks}")
    '''
)


def run(tmp_path, fail: str, *args: str, on_failure: str | None = None) -> subprocess.CompletedProcess[str]:
    (tmp_path / "faulty.py").write_text(NODES)
    extra = f'on_failure = "{on_failure}"\n' if on_failure else ""
    (tmp_path / "g.toml").write_text(f'[[nodes]]\nuse = "faulty:Faulty"\n{extra}parameters = {{ fail = "{fail}" }}\n')
    return subprocess.run(
        [AIOROBOT, "run", "g.toml", *args], cwd=tmp_path, capture_output=True, text=True, timeout=60
    )


def test_a_raising_callback_makes_the_run_exit_1_with_one_traceback_and_a_summary(tmp_path):
    result = run(tmp_path, "callback", "--duration", "1")
    assert result.returncode == 1, result.stderr
    assert result.stderr.count("Traceback") == 1
    assert "ValueError: bad reading 1" in result.stderr
    assert "failures:\n  /faulty: callback of timer 0.01s raised " in result.stderr


def test_a_clean_run_exits_0(tmp_path):
    result = run(tmp_path, "nothing", "--duration", "0.5")
    assert result.returncode == 0, result.stderr
    assert "failures:" not in result.stderr


def test_a_failed_start_stops_the_run_and_exits_1(tmp_path):
    result = run(tmp_path, "on_start", "--duration", "600")  # stops long before the duration
    assert result.returncode == 1, result.stderr
    assert "/faulty failed to start (RuntimeError: motor driver not found); stopping the run" in result.stderr
    assert "  /faulty: failed to start (on_start raised)" in result.stderr


def test_keep_going_keeps_the_other_callbacks_running_but_still_exits_1(tmp_path):
    result = run(tmp_path, "on_start", "--duration", "1", "--keep-going")
    assert result.returncode == 1, result.stderr
    assert "tick 20" in result.stdout
    assert "stopping the run" not in result.stderr


def test_on_failure_continue_in_the_config(tmp_path):
    result = run(tmp_path, "on_start", "--duration", "1", on_failure="continue")
    assert result.returncode == 1 and "tick 20" in result.stdout


SCRIPT = textwrap.dedent(
    '''
    import logging, sys
    import aiorobot
    from aiorobot import Node, Runtime

    if sys.argv[1] == "configured":
        logging.basicConfig(level=logging.WARNING, format="APP %(levelname)s %(message)s")

    async def main():
        async with Runtime() as rt:
            node = rt.add_node(Node("talker"))
            node.get_logger().info("hello")
            node.get_logger().warning("careful")
            node.get_logger().debug("hidden")

    aiorobot.run(main())
    '''
)


def test_node_loggers_print_info_to_stderr_by_default(tmp_path):
    (tmp_path / "s.py").write_text(SCRIPT)
    result = subprocess.run([sys.executable, "s.py", "plain"], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    lines = result.stderr.splitlines()
    assert [line.split("] [")[0] + "]" for line in lines] == ["[INFO]", "[WARN]"]
    assert lines[0].endswith("] [/talker]: hello") and lines[1].endswith("] [/talker]: careful")


def test_an_application_that_configures_logging_keeps_its_own_format(tmp_path):
    (tmp_path / "s.py").write_text(SCRIPT)
    result = subprocess.run([sys.executable, "s.py", "configured"], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert result.stderr.splitlines() == ["APP WARNING careful"]


def test_run_of_a_python_file_says_it_expects_a_toml_graph(tmp_path):
    (tmp_path / "node.py").write_text("raise SystemExit('must not be imported')\n")
    result = subprocess.run([AIOROBOT, "run", "node.py"], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert result.returncode == 2
    assert result.stderr.splitlines() == [
        "node.py: expected a TOML graph file (aiorobot run graph.toml), found a Python file; "
        "to run one node class from it, use aiorobot run node:ClassName"
    ]


OFFLOAD = textwrap.dedent(
    '''
    import math
    import aiorobot
    from aiorobot import Node, Runtime

    async def main():
        async with Runtime(process_workers=1) as rt:
            node = rt.add_node(Node("worker"))
            print(await node.offload(math.sqrt, 4.0))

    {call}
    '''
)


def test_offload_from_a_script_without_the_main_guard_says_what_to_add(tmp_path):
    (tmp_path / "unguarded.py").write_text(OFFLOAD.format(call="aiorobot.run(main())"))
    result = subprocess.run([sys.executable, "unguarded.py"], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert result.returncode == 1
    assert result.stderr.splitlines()[-1] == (
        "RuntimeError: offload starts worker processes that import unguarded.py: put its entry point under "
        '`if __name__ == "__main__":` (e.g. `if __name__ == "__main__": aiorobot.run(main())`)'
    )
    assert "bootstrapping" not in result.stderr


def test_offload_from_a_guarded_script_works(tmp_path):
    (tmp_path / "guarded.py").write_text(OFFLOAD.format(call='if __name__ == "__main__":\n    aiorobot.run(main())'))
    result = subprocess.run([sys.executable, "guarded.py"], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "2.0"


def test_square_cmd_vel_example_prints_its_pattern_when_run():
    from pathlib import Path

    examples = Path(__file__).resolve().parents[2] / "examples"
    result = subprocess.run([sys.executable, "square_cmd_vel.py"], cwd=examples, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert "linear.x=+0.30" in result.stdout
    assert "aiorobot run examples/mecanum_serial.toml" in result.stdout


def test_on_failure_stays_with_its_own_node_when_a_recorder_runs_first(tmp_path):
    """[record] puts the recorder before the file's nodes: each node still gets its own table's
    on_failure (it went to the node one place later, so "continue" here stopped the run)."""
    (tmp_path / "faulty.py").write_text(NODES)
    (tmp_path / "g.toml").write_text(
        '[record]\npath = "run"\n\n'
        '[[nodes]]\nuse = "faulty:Faulty"\nname = "ok"\nparameters = { fail = "nothing" }\n\n'
        '[[nodes]]\nuse = "faulty:Faulty"\nname = "flaky"\non_failure = "continue"\n'
        'parameters = { fail = "on_start" }\n'
    )
    result = subprocess.run(
        [AIOROBOT, "run", "g.toml", "--duration", "1"], cwd=tmp_path, capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 1, result.stderr
    assert "/flaky: failed to start (on_start raised)" in result.stderr
    assert "stopping the run" not in result.stderr
    assert "tick 20" in result.stdout  # the run went on for its duration


def test_node_configs_pairs_each_built_node_with_its_table(tmp_path):
    from aiorobot.launch import build_nodes, load_config, node_configs

    (tmp_path / "faulty.py").write_text(NODES)
    (tmp_path / "g.toml").write_text(
        '[runtime]\nfoxglove = { port = 0 }\n\n[record]\npath = "run"\n\n'
        '[[nodes]]\nuse = "faulty:Faulty"\nname = "a"\n\n'
        '[[nodes]]\nuse = "faulty:Faulty"\nname = "b"\nprocess = "worker"\n\n'
        '[[nodes]]\nuse = "faulty:Faulty"\nname = "c"\n\n'
        '[processes.worker]\n'
    )
    config = load_config(tmp_path / "g.toml")
    try:
        main = build_nodes(config)
        worker = build_nodes(config, "worker")
    finally:
        sys.path.remove(str(tmp_path)) if str(tmp_path) in sys.path else None
    assert [t.name if t else None for t in node_configs(config, main)] == [None, "a", "c", None]
    assert [n.get_name() for n, _ in main][1:3] == ["a", "c"]
    assert [t.name for t in node_configs(config, worker, "worker")] == ["b"]
