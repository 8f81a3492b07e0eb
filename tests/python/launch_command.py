"""Read a launch_ros launch file with `ast` (no ROS 2 needed) and print, as
JSON, the command line launch_ros would run for its Node action.

    python3 launch_command.py LAUNCH_FILE SHARE_DIR TMP_DIR [NAME:=VALUE ...]

SHARE_DIR stands for get_package_share_directory(<the package>); TMP_DIR
receives the parameter file launch_ros writes for dict parameters. Launch
arguments take their declared defaults unless given as NAME:=VALUE.

The command is built as launch_ros (Humble and later) builds it:
  <executable> <arguments...> [--ros-args <ros_arguments...>]
  --ros-args -r __node:=NAME [-r __ns:=NS] --params-file F... -r FROM:=TO...
where a dict in `parameters` becomes a temporary file `/**: ros__parameters:`.

Only what a plain launch file uses is understood (constants, module-level
names, os.path.join, get_package_share_directory, LaunchConfiguration,
lists, tuples and dicts); anything else is an error naming the construct.
"""

import ast
import json
import os
import sys


class Unsupported(Exception):
    pass


def main():
    launch_file, share, tmp = sys.argv[1:4]
    overrides = dict(a.split(':=', 1) for a in sys.argv[4:])
    tree = ast.parse(open(launch_file, encoding='utf-8').read(), launch_file)
    consts = {}
    for node in tree.body:
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Constant):
            for t in node.targets:
                consts[t.id] = node.value.value
    gen = next(n for n in tree.body
               if isinstance(n, ast.FunctionDef) and n.name == 'generate_launch_description')
    local = dict(consts)
    declared = {}

    def ev(e):
        if isinstance(e, ast.Constant):
            return e.value
        if isinstance(e, ast.Name):
            if e.id in local:
                return local[e.id]
            raise Unsupported(f'unknown name {e.id} (line {e.lineno})')
        if isinstance(e, (ast.List, ast.Tuple)):
            return [ev(x) for x in e.elts]
        if isinstance(e, ast.Dict):
            return {ev(k): ev(v) for k, v in zip(e.keys, e.values)}
        if isinstance(e, ast.Call):
            name = ast.unparse(e.func)
            args = [ev(a) for a in e.args]
            if name == 'os.path.join':
                return os.path.join(*args)
            if name == 'get_package_share_directory':
                return share
            if name == 'LaunchConfiguration':
                if args[0] in overrides:
                    return overrides[args[0]]
                if args[0] not in declared:
                    raise Unsupported(f'launch argument {args[0]} is not declared')
                return declared[args[0]]
            raise Unsupported(f'call {name} (line {e.lineno})')
        raise Unsupported(f'{type(e).__name__} (line {e.lineno})')

    node_kwargs = None
    for stmt in gen.body:
        if isinstance(stmt, ast.Assign):
            value = ev(stmt.value)
            for t in stmt.targets:
                local[t.id] = value
        elif isinstance(stmt, ast.Return):
            actions = stmt.value.args[0].elts
            for a in actions:
                kind = ast.unparse(a.func)
                kw = {k.arg: k.value for k in a.keywords}
                if kind == 'DeclareLaunchArgument':
                    declared[ev(a.args[0])] = ev(kw['default_value'])
                elif kind == 'Node':
                    node_kwargs = kw
                else:
                    raise Unsupported(f'action {kind}')
    if node_kwargs is None:
        raise Unsupported('no Node action')
    kw = {k: ev(v) for k, v in node_kwargs.items()}
    cmd = [kw['executable']] + list(kw.get('arguments', []))
    if kw.get('ros_arguments'):
        cmd += ['--ros-args'] + list(kw['ros_arguments'])
    cmd += ['--ros-args']
    if kw.get('name'):
        cmd += ['-r', f"__node:={kw['name']}"]
    ns = kw.get('namespace')
    if ns is not None:
        ns = '/' + ns.strip('/')
        cmd += ['-r', f'__ns:={ns}']
    for i, p in enumerate(kw.get('parameters', [])):
        if isinstance(p, dict):
            path = os.path.join(tmp, f'launch_params_{i}.yaml')
            with open(path, 'w', encoding='utf-8') as f:
                f.write('/**:\n  ros__parameters:\n')
                for k, v in p.items():
                    f.write(f'    {k}: {v}\n')
            cmd += ['--params-file', path]
        else:
            cmd += ['--params-file', p]
    for frm, to in kw.get('remappings', []):
        cmd += ['-r', f'{frm}:={to}']
    print(json.dumps({'package': kw['package'], 'executable': kw['executable'],
                      'declared': declared, 'command': cmd}))


if __name__ == '__main__':
    try:
        main()
    except Unsupported as e:
        print(f'launch_command.py: unsupported: {e}', file=sys.stderr)
        sys.exit(2)
