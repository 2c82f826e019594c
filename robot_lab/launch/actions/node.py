"""`<node>`/launch_ros.actions.Node: the command line launch_ros builds."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from robot_lab.launch.action import LaunchStep, opt_subs, subs
from robot_lab.launch.actions.execute_process import (
    ExecuteStep,
    ProcessOptions,
    parse_process_options,
)
from robot_lab.launch.entity import Entity, required, split_cmdline, sub_attr
from robot_lab.launch.names import (
    absolute_namespace,
    namespace_problem,
    node_name_problem,
    prefix_namespace,
)
from robot_lab.launch.parameters import (
    NodeParameters,
    ParamFileRef,
    check_param_file,
    flatten_params,
    parse_param_entities,
    substituted_param_file,
)
from robot_lab.launch.registry import register
from robot_lab.launch.substitutions import SomeSubstitutions, perform
from robot_lab.params import write_param_file

if TYPE_CHECKING:
    from robot_lab.launch.context import LaunchContext

__all__ = ['NodeStep']


@register('node')
class NodeStep(ExecuteStep):
    """`<node>` / launch_ros.actions.Node: the command line launch_ros builds."""

    launch_name = 'Node'

    def __init__(self, executable: SomeSubstitutions, package: SomeSubstitutions | None = None,
                 name: SomeSubstitutions | None = None,
                 namespace: SomeSubstitutions | None = None,
                 exec_name: SomeSubstitutions | None = None,
                 parameters: Sequence[NodeParameters] | None = None,
                 remappings: Iterable[tuple[SomeSubstitutions, SomeSubstitutions]] | None = None,
                 ros_arguments: Sequence[SomeSubstitutions] | None = None,
                 arguments: Sequence[SomeSubstitutions] | None = None,
                 options: ProcessOptions | None = None) -> None:
        options = options or ProcessOptions()
        if exec_name is not None:
            options.name = subs(exec_name)
        super().__init__([], options)
        self.executable = subs(executable)
        self.package = opt_subs(package)
        self.name = opt_subs(name)
        self.namespace = opt_subs(namespace)
        self.parameters = list(parameters or [])
        self.remappings = [(subs(a), subs(b)) for a, b in (remappings or [])]
        self.ros_arguments = None if ros_arguments is None else [subs(a) for a in ros_arguments]
        self.arguments = [subs(a) for a in (arguments or [])]

    def execute(self, context: LaunchContext) -> None:
        executable = perform(self.executable, context)
        package = perform(self.package, context) if self.package is not None else None
        if package is not None:
            from robot_lab.pkg.index import find_executable

            path = str(find_executable(package, executable, context.environment))
        else:
            path = executable
        cmd = [path, *(perform(a, context) for a in self.arguments)]
        if self.ros_arguments is not None:
            cmd += ['--ros-args', *(perform(a, context) for a in self.ros_arguments)]
        cmd.append('--ros-args')
        name = None
        if self.name is not None:
            name = perform(self.name, context)
            problem = node_name_problem(name)
            if problem:
                raise context.error(f"Invalid node name '{name}': {problem}")
            cmd += ['-r', f'__node:={name}']
        namespace = absolute_namespace(prefix_namespace(
            context.ros['ros_namespace'],
            perform(self.namespace, context) if self.namespace is not None else None))
        if namespace is not None:
            problem = namespace_problem(namespace)
            if problem:
                raise context.error(f"Invalid namespace '{namespace}': {problem}")
            cmd += ['-r', f'__ns:={namespace}']
        # launch_ros keys name/value files by the node's full name only when both name and
        # namespace are known; otherwise ('/**') they reach every node of the process
        fqn = prefix_namespace(namespace, name) if name is not None and namespace else None
        param_files: list[str] = []
        for entry in context.ros['global_params'] or []:
            if isinstance(entry, tuple):
                cmd += ['-p', f'{entry[0]}:={entry[1]}']
            else:
                cmd += ['--params-file', entry]
                param_files.append(entry)
        for entry in self.parameters:
            if isinstance(entry, ParamFileRef):
                with context.located(entry.where):  # an error names the <param>'s line
                    file = str(Path(perform(entry.path, context)))  # as ParameterFile.evaluate
                if entry.allow_substs:
                    file = substituted_param_file(file, context)
                check_param_file(file, context)
                cmd += ['--params-file', file]
                param_files.append(file)
            elif isinstance(entry, Mapping):
                values = flatten_params(entry, context)
                written = write_param_file(values, fqn or '/**')
                cmd += ['--params-file', str(written)]
                param_files.append(str(written))
            else:
                raise context.error(f'invalid normalized parameters {entry!r}')
        remaps = list(context.ros['ros_remaps'] or [])
        remaps += [(perform(a, context), perform(b, context)) for a, b in self.remappings]
        for src, dst in remaps:
            cmd += ['-r', f'{src}:={dst}']
        full_name = None
        if name is not None:
            full_name = prefix_namespace(namespace or '/', name)
        spec = self._spec(context, cmd, node_name=full_name, package=package,
                          executable=executable, param_files=param_files)
        context.sink.append(spec)
        self.register_on_exit(context)

    @classmethod
    def parse(cls, e: Entity) -> LaunchStep:
        options = parse_process_options(e)
        options.name = None  # on a node, `name` is the node's name; exec_name names the process
        args = e.attr('args')
        ros_args = e.attr('ros_args')
        remaps = e.entities('remap') or []
        pairs = [(required(r, 'from'), required(r, 'to')) for r in remaps]
        for r in remaps:
            r.assert_parsed()
        params = e.entities('param')
        return cls(
            required(e, 'exec'), package=sub_attr(e, 'pkg'), name=sub_attr(e, 'name'),
            namespace=sub_attr(e, 'namespace'), exec_name=sub_attr(e, 'exec_name'),
            parameters=parse_param_entities(params) if params is not None else None,
            remappings=pairs,
            ros_arguments=split_cmdline(ros_args) if ros_args is not None else None,
            arguments=split_cmdline(args) if args is not None else None,
            options=options,
        )
