"""Start friction-node from a ROS 2 launch file.

    ros2 launch friction-node friction_node.launch.py
    ros2 launch friction-node friction_node.launch.py \
        cmd_velocity_topic:=/axis_x/velocity_command params_file:=/path/to/machine.yaml

The node is the `friction-node` binary of the `friction-node` package (built
by colcon with colcon-ros-cargo; see the README). The launch arguments:

| argument            | default                                  | meaning                                    |
|---------------------|------------------------------------------|--------------------------------------------|
| params_file         | <share>/launch-config/default.yaml       | ROS 2 parameter file (every key: README)   |
| node_name           | friction_node                            | the node's name (also the params-file key) |
| namespace           | ''                                       | the node's namespace                       |
| cmd_velocity_topic  | /slider/cmd_velocity                     | where the commanded velocity comes from    |
| friction_topic      | ~/friction                               | where the estimate goes                    |
| use_sim_time        | false                                    | timer mode follows /clock                  |
| log_level           | info                                     | debug, info, warn, error, fatal            |

`tests/launch_file.rs` reads this file with Python's `ast` (it cannot run
here without ROS 2) and checks that the executable, parameter file and
remappings it passes are accepted by the node (`friction-node run --check`).
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

PACKAGE = 'friction-node'
EXECUTABLE = 'friction-node'


def generate_launch_description():
    default_params = os.path.join(
        get_package_share_directory(PACKAGE), 'launch-config', 'default.yaml')
    return LaunchDescription([
        DeclareLaunchArgument(
            'params_file', default_value=default_params,
            description='ROS 2 parameter file for the node'),
        DeclareLaunchArgument(
            'node_name', default_value='friction_node',
            description="The node's name (the key its parameter file uses)"),
        DeclareLaunchArgument(
            'namespace', default_value='',
            description="The node's namespace"),
        DeclareLaunchArgument(
            'cmd_velocity_topic', default_value='/slider/cmd_velocity',
            description='Commanded slider velocity (std_msgs/Float64, m/s)'),
        DeclareLaunchArgument(
            'friction_topic', default_value='~/friction',
            description='Friction estimate (friction_msgs/FrictionEstimate)'),
        DeclareLaunchArgument(
            'use_sim_time', default_value='false',
            description='Step on /clock (rosgraph_msgs/Clock) instead of the wall clock'),
        DeclareLaunchArgument(
            'log_level', default_value='info',
            description='debug, info, warn, error or fatal'),
        Node(
            package=PACKAGE,
            executable=EXECUTABLE,
            name=LaunchConfiguration('node_name'),
            namespace=LaunchConfiguration('namespace'),
            arguments=['run', '--quiet'],
            parameters=[
                LaunchConfiguration('params_file'),
                {'use_sim_time': LaunchConfiguration('use_sim_time')},
            ],
            remappings=[
                ('~/cmd_velocity', LaunchConfiguration('cmd_velocity_topic')),
                ('~/friction', LaunchConfiguration('friction_topic')),
            ],
            ros_arguments=['--log-level', LaunchConfiguration('log_level')],
            output='screen',
            emulate_tty=True,
        ),
    ])
