"""gesturecast.realtime"""
