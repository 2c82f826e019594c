"""A `%%bash` cell's output as the program wrote it, on IPython 8 (Python 3.10) too.

IPython 8's script magics (`%%bash`, `%%sh`, `%%script`, ...) read a program's output 100
bytes at a time and decode each piece on its own, so a character that straddles two reads
comes out as two U+FFFD: the `°C` at byte 100 of a refused `ros2 param set` printed `��C`
in 04_parameters on Python 3.10. IPython 9 decodes incrementally, but needs Python 3.11,
and 8.39 (the last 8.x) still splits. So on IPython 8 a lesson's set-up registers these
magics again, reading both streams with incremental decoders; a cell that asks for --bg,
--out, --err or --proc keeps IPython's own code (no lesson does).
"""

from __future__ import annotations

import codecs
import errno
import os
import selectors
import shlex
import signal
import subprocess
import sys
from collections.abc import Callable
from typing import IO, Any

__all__ = ['decode_whole_characters', 'run_script']

_CHUNK = 4096


def decode_whole_characters() -> None:
    """On IPython 8, this shell's script magics decode what a program prints incrementally."""
    try:
        import IPython
        from IPython import get_ipython
    except ImportError:
        return
    shell = get_ipython()
    if shell is None or int(IPython.__version__.split('.')[0]) >= 9:
        return
    magics = shell.magics_manager.registry.get('ScriptMagics')
    if magics is None:
        return
    cell_magics = shell.magics_manager.magics['cell']
    for name in ['script', *magics.script_magics]:
        original = cell_magics.get(name)
        if original is not None and not getattr(original, '_robot_lab_whole', False):
            program = None if name == 'script' else magics.script_paths.get(name, name)
            shell.register_magic_function(_whole(program, original), 'cell', name)


def _whole(program: str | None, original: Callable[[str, str], Any]) -> Callable[[str, str], Any]:
    """`%%script` (program None) or `%%bash` and the like (program 'bash', ...)."""
    def magic(line: str, cell: str) -> Any:
        from IPython.core.magics.script import ScriptMagics

        full = line if program is None else f'{program} {line}'.rstrip()
        args, cmd = ScriptMagics.shebang.parser.parse_known_args(shlex.split(full))
        if args.bg or args.out or args.err or args.proc:
            return original(line, cell)
        return run_script(cmd, cell, raise_error=args.raise_error)

    magic.__doc__ = original.__doc__
    magic._robot_lab_whole = True  # type: ignore[attr-defined]
    return magic


def run_script(cmd: list[str], cell: str, *, raise_error: bool = True) -> None:
    """Run `cell` through `cmd` as IPython's `%%script` does, its output decoded whole."""
    try:
        process = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE)
    except OSError as err:
        if err.errno == errno.ENOENT:
            print(f"Couldn't find program: {cmd[0]!r}")
            return
        raise
    script = (cell if cell.endswith('\n') else cell + '\n').encode('utf8', 'replace')
    try:
        _communicate(process, script, sys.stdout, sys.stderr)
        process.wait()
    except KeyboardInterrupt:
        _interrupt(process)
        if raise_error:
            raise subprocess.CalledProcessError(process.returncode or -9, cell) from None
        return
    finally:
        for pipe in (process.stdin, process.stdout, process.stderr):
            if pipe is not None:
                pipe.close()
    if raise_error and process.returncode != 0:
        raise subprocess.CalledProcessError(process.returncode, cell)


def _communicate(process: subprocess.Popen[bytes], script: bytes, out: IO[str],
                 err: IO[str]) -> None:
    """Feed the script and copy both streams, in the order they come, until both close."""
    assert process.stdin and process.stdout and process.stderr
    with selectors.DefaultSelector() as selector:
        for pipe, stream in ((process.stdout, out), (process.stderr, err)):
            decoder = codecs.getincrementaldecoder('utf-8')(errors='replace')
            selector.register(pipe, selectors.EVENT_READ, (stream, decoder))
        os.set_blocking(process.stdin.fileno(), False)
        selector.register(process.stdin, selectors.EVENT_WRITE, None)
        while selector.get_map():
            for key, _ in selector.select():
                if key.data is None:  # the script, as much as the pipe takes
                    try:
                        script = script[os.write(key.fd, script):]
                    except BrokenPipeError:
                        script = b''  # the program stopped reading (exit in the cell)
                    if not script:
                        selector.unregister(key.fileobj)
                        process.stdin.close()
                    continue
                stream, decoder = key.data
                chunk = os.read(key.fd, _CHUNK)
                text = decoder.decode(chunk, final=not chunk)
                if text:
                    stream.write(text)
                    stream.flush()
                if not chunk:
                    selector.unregister(key.fileobj)


def _interrupt(process: subprocess.Popen[bytes]) -> None:
    """Stop the program as IPython does: Ctrl-C, then SIGTERM, then SIGKILL."""
    steps: list[tuple[Callable[[], None], str]] = [
        (lambda: process.send_signal(signal.SIGINT), 'Process was interrupted.'),
        (process.terminate, 'Process was terminated.')]
    try:
        for send, said in steps:
            send()
            try:
                process.wait(timeout=0.1)
            except subprocess.TimeoutExpired:
                continue
            print(said)
            return
        process.kill()
        print('Process was killed.')
    except OSError:
        pass
