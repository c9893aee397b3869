"""``sys.exit()`` in a callback ends the program with its code, as asyncio ends it for any callback
of its loop: cleanly, with the runtime shut down, and with no traceback. On the priority loop it
used to end that loop's thread silently (the program ran on with its control nodes stopped, and its
shutdown failed with "Event loop is closed"); on the main loop asyncio printed "Task exception was
never retrieved" for the timer's task."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

PROGRAM = textwrap.dedent("""
    import asyncio, sys
    from aiorobot import Node, Runtime, ServiceError
    from aiorobot.msgs.std_srvs import Trigger

    async def main():
        try:
            async with Runtime(handle_signals=False) as rt:
                node = rt.add_node(Node("quitter"), executor=EXECUTOR)
                ticks = []

                def tick():
                    ticks.append(1)
                    if len(ticks) == 3:
                        sys.exit(4)

                async def task():
                    await asyncio.sleep(0.03)
                    sys.exit(4)

                if HOW == "timer":
                    node.create_timer(0.01, tick)
                elif HOW == "task":
                    node.create_task(task())
                elif HOW == "service":
                    node.create_service(Trigger, "/quit", lambda request, response: sys.exit(4))
                    client = rt.add_node(Node("caller")).create_client(Trigger, "/quit")
                    try:
                        await client.call_async(Trigger.Request())
                    except ServiceError as err:
                        print("the caller was told:", err, flush=True)
                    await asyncio.sleep(30)
                else:  # on_start
                    class Quitter(Node):
                        async def on_start(self):
                            sys.exit(4)

                    rt.add_node(Quitter("starter"), executor=EXECUTOR)
                await asyncio.sleep(30)
                print("the program ran on", flush=True)
        finally:
            print("runtime closed", flush=True)

    asyncio.run(main())
""")


@pytest.mark.parametrize("executor", ["main", "priority"])
@pytest.mark.parametrize("how", ["timer", "task", "service", "on_start"])
def test_sys_exit_in_a_callback_or_task_ends_the_program_with_its_code(tmp_path, executor, how):
    script = tmp_path / "quitter.py"
    script.write_text(f"EXECUTOR = {executor!r}\nHOW = {how!r}\n" + PROGRAM)
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 4, done.stdout + done.stderr
    lines = done.stdout.splitlines()
    assert lines[-1:] == ["runtime closed"] and "the program ran on" not in done.stdout, done.stdout + done.stderr
    assert "Traceback" not in done.stderr and "never retrieved" not in done.stderr, done.stderr
