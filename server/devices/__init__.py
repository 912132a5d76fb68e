"""server/devices"""
