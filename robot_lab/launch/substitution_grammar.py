"""The `$(name arg ...)` grammar (ros2/launch frontend/grammar.lark) and the name table.

Text with `$(name arg ...)` parts, arguments separated by spaces, quoted with '..' or
"..", substitutions nested, `\\x` escapes x. A new substitution is its class and one line
in SUBSTITUTIONS.
"""

from __future__ import annotations

from collections.abc import Callable

from robot_lab.launch.boolean_substitutions import (
    AllTrue,
    And,
    AnyTrue,
    Equals,
    IfElse,
    Not,
    NotEquals,
    Or,
)
from robot_lab.launch.substitutions import (
    AnonName,
    Command,
    EnvironmentVariable,
    ExecutableInPackage,
    FileContent,
    FindExecutable,
    FindPackagePrefix,
    FindPackageShare,
    LaunchConfiguration,
    LaunchLogDir,
    PythonExpression,
    Subs,
    Substitution,
    Text,
    ThisLaunchFile,
    ThisLaunchFileDir,
)

__all__ = ['SUBSTITUTIONS', 'parse_substitution']


def _arity(name: str, low: int, high: int) -> Callable[[list[Subs]], None]:
    def check(args: list[Subs]) -> None:
        if not low <= len(args) <= high:
            count = str(low) if low == high else f'{low} or {high}' if high == low + 1 \
                else f'{low} to {high}'
            plural = 'argument' if count == '1' else 'arguments'
            raise ValueError(f'{name} substitution expects {count} {plural}')
    return check


SUBSTITUTIONS: dict[str, tuple[Callable[..., Substitution], int, int]] = {
    'var': (LaunchConfiguration, 1, 2),
    'env': (EnvironmentVariable, 1, 2),
    'eval': (PythonExpression, 1, 2),
    'command': (Command, 1, 2),
    'anon': (AnonName, 1, 1),
    'dirname': (ThisLaunchFileDir, 0, 0),
    'filename': (ThisLaunchFile, 0, 0),
    'find-exec': (FindExecutable, 1, 1),
    'find-pkg-share': (FindPackageShare, 1, 1),
    'find-pkg-prefix': (FindPackagePrefix, 1, 1),
    'exec-in-pkg': (ExecutableInPackage, 2, 2),
    'file-content': (FileContent, 1, 1),
    'if': (IfElse, 2, 3),
    'not': (Not, 1, 1),
    'and': (And, 2, 2),
    'or': (Or, 2, 2),
    'equals': (Equals, 2, 2),
    'not-equals': (NotEquals, 2, 2),
    'any': (AnyTrue, 1, 99),
    'all': (AllTrue, 1, 99),
    'log_dir': (LaunchLogDir, 0, 0),
    'launch_log_dir': (LaunchLogDir, 0, 0),
}


class _Reader:
    """Recursive descent over launch's substitution grammar."""

    def __init__(self, text: str) -> None:
        self.text = text
        self.pos = 0

    def peek(self, count: int = 1) -> str:
        return self.text[self.pos:self.pos + count]

    def error(self, message: str) -> ValueError:
        return ValueError(f'{message} in {self.text!r} at column {self.pos + 1}')

    def scan(self, quote: str | None, stops: str = '') -> tuple[Subs, bool]:
        """Text (with `\\` escapes) and nested `$(...)` up to a character in `stops`.

        The stop character is not consumed; the flag says whether one was reached (False:
        the text ended). The top level, unquoted arguments and quoted strings all read
        with this one loop and differ only in where they stop.
        """
        parts: Subs = []
        buffer: list[str] = []

        def flush() -> None:
            if buffer:
                parts.append(Text(''.join(buffer)))
                buffer.clear()

        while self.pos < len(self.text):
            char = self.peek()
            if self.peek(2) == '$(':
                flush()
                parts.append(self.substitution(quote))
            elif char == '\\' and self.pos + 1 < len(self.text):
                buffer.append(self.text[self.pos + 1])
                self.pos += 2
            elif char in stops:
                flush()
                return parts, True
            else:
                buffer.append(char)
                self.pos += 1
        flush()
        return parts, False

    def template(self) -> Subs:
        """Top level: anything is text except `$(`."""
        return self.scan(None)[0]

    def substitution(self, quote: str | None) -> Substitution:
        self.pos += 2  # '$('
        start = self.pos
        while self.pos < len(self.text) and (
            self.peek().isalnum() or self.peek() in '_-'
        ):
            self.pos += 1
        name = self.text[start:self.pos]
        if not name or not name[0].isalpha():
            raise self.error('expected a substitution name after "$("')
        args: list[Subs] = []
        while self.peek() == ' ':
            while self.peek() == ' ':
                self.pos += 1
            if self.peek() == ')':
                break
            args.append(self.value(quote))
        if self.peek() != ')':
            raise self.error(f'expected ")" to close $({name}')
        self.pos += 1
        if name not in SUBSTITUTIONS:
            raise ValueError(f'Unknown substitution: {name}')
        factory, low, high = SUBSTITUTIONS[name]
        _arity(name, low, high)(args)
        return factory(*args)

    def value(self, quote: str | None) -> Subs:
        if quote is None and self.peek() in ('"', "'"):
            return self.quoted(self.peek())
        parts, _ = self.scan(quote, ' ()"\'')
        if not parts:
            raise self.error('expected a substitution argument')
        return parts

    def quoted(self, quote: str) -> Subs:
        self.pos += 1
        parts, closed = self.scan(quote, quote)
        if not closed:
            raise self.error(f'unterminated {quote} quote')
        self.pos += 1
        return parts or [Text('')]


def parse_substitution(text: str) -> Subs:
    """`'$(find-pkg-share p)/config/$(var f)'` -> substitutions; ValueError if malformed."""
    if not text:
        return [Text('')]
    return _Reader(text).template()
