# The lfd_tools Python package (lfd_tools/src/lfd_tools), installed into the devel space by
# catkin_python_setup(): every lfd script imports it after `source devel/setup.bash`.
from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(packages=["lfd_tools"], package_dir={"": "src"}))
