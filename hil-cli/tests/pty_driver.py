"""Drives `hil run` with a terminal channel through a real pseudo-terminal.

Usage: pty_driver.py MODE HIL ARGS...
MODE is `answer-all`, `interrupt-after-N` (answer N prompts, then Ctrl-C)
or `eof-after-N` (answer N prompts, then Ctrl-D). Prints one JSON object:
the exit code or signal, the number of prompts answered and the output.
"""
import json
import os
import pty
import select
import sys
import time

TIMEOUT_S = 30.0


def answer_for(screen):
    """The answer a person would type for the last prompt on the screen."""
    last = screen[screen.rfind("The robot asks"):]
    if "Kind: multiple choice" in last:
        return "2"
    if "Kind: bounding box" in last:
        return "0.25 0.3 0.75 0.8"
    return "try TA0"


def main():
    mode, argv = sys.argv[1], sys.argv[2:]
    pid, fd = pty.fork()
    if pid == 0:
        os.execv(argv[0], argv)
    limit = None
    action = None
    if mode.startswith("interrupt-after-"):
        limit, action = int(mode.rsplit("-", 1)[1]), b"\x03"
    elif mode.startswith("eof-after-"):
        limit, action = int(mode.rsplit("-", 1)[1]), b"\x04"
    screen, answered, sent_action = "", 0, False
    seen_prompts = 0
    deadline = time.monotonic() + TIMEOUT_S
    while time.monotonic() < deadline:
        ready, _, _ = select.select([fd], [], [], 0.2)
        if ready:
            try:
                data = os.read(fd, 4096)
            except OSError:
                break  # the child closed the terminal
            if not data:
                break
            screen += data.decode("utf-8", "replace")
            prompts = screen.count("answer> ")
            if prompts > seen_prompts:
                seen_prompts = prompts
                if limit is not None and answered >= limit:
                    if not sent_action:
                        os.write(fd, action)
                        sent_action = True
                else:
                    os.write(fd, (answer_for(screen) + "\r").encode())
                    answered += 1
    else:
        os.kill(pid, 9)
    _, status = os.waitpid(pid, 0)
    result = {
        "answered": answered,
        "exit_code": os.WEXITSTATUS(status) if os.WIFEXITED(status) else None,
        "signal": os.WTERMSIG(status) if os.WIFSIGNALED(status) else None,
        "output": screen,
    }
    print(json.dumps(result))


main()
