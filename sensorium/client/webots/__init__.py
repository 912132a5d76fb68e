"""client/webots"""
