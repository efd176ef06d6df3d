"""IMU logs: from a logger's files to a block's rotation and a table's acceleration.

- readers for x-IMU (GUI export with its registers), x-IMU3 and x-io Fusion CSV logs
  (:func:`read_imu`, :class:`ImuLog`), with the sample rate from the registers or the
  timestamps;
- a block's rotation about its rocking axis: AHRS (imufusion) or the gyro's integral held
  to the accelerometer's tilt at rest (:func:`block_rotation`, :class:`ImuRotation`);
- a table's horizontal acceleration (:func:`table_acceleration`).
"""

from ._read import ImuLog, imu_log_files, read_imu, read_ximu_registers, ximu_rate_from_registers
from ._rotation import ImuRotation, ahrs_quaternions, ahrs_rotation, block_rotation
from ._table import TableAcceleration, table_acceleration

__all__ = [
    "ImuLog",
    "read_imu",
    "imu_log_files",
    "read_ximu_registers",
    "ximu_rate_from_registers",
    "ImuRotation",
    "block_rotation",
    "ahrs_rotation",
    "ahrs_quaternions",
    "TableAcceleration",
    "table_acceleration",
]
