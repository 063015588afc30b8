"""gesturecast.bridges"""
