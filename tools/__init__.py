"""gesturecast.tools"""
