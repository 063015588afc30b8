"""gesturecast.models"""
