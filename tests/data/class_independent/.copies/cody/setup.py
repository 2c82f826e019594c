from setuptools import setup

setup(
    name='line_tracer',
    version='0.1.0',
    packages=['line_tracer'],
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/line_tracer']),
        ('share/line_tracer', ['package.xml', 'launch/tracer.launch.yaml',
                               'config/tracer.yaml']),
        ('share/line_tracer/launch', ['launch/tracer.launch.yaml']),
        ('share/line_tracer/config', ['config/tracer.yaml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Chen',
    maintainer_email='chen@example.com',
    description='Line following',
    license='BSD-3-Clause',
    entry_points={'console_scripts': [
        'camera = line_tracer.camera:main',
        'steering = line_tracer.steering:main',
        'motors = line_tracer.motors:main',
    ]},
)
