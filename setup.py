# The package's Python package (src/joint_load_estimator), for catkin_python_setup():
# installed beside the generated joint_load_estimator.msg and the extension module
# joint_load_estimator._core (src/python/CMakeLists.txt). Not to be run by hand.
from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(packages=["joint_load_estimator"], package_dir={"": "src"}))
