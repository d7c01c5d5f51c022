"""Python packaging for catkin (catkin_python_setup); do not run it by hand."""
from setuptools import setup

try:
    from catkin_pkg.python_setup import generate_distutils_setup
except ImportError:  # plain setuptools, outside a catkin build
    def generate_distutils_setup(**kwargs):  # type: ignore[no-untyped-def]
        return kwargs

setup(**generate_distutils_setup(
    packages=["rubass", "rubass.lang", "rubass.engine", "rubass.replay", "rubass.ros", "rubass.ros.actions",
              "rubass_experiments", "rubass.actions", "rubass.testing", "rubass.report"],
))
