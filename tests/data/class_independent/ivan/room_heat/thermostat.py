# Thermostat node: bang-bang control with a band around the set point
import rclpy
from rclpy.node import Node
from sensor_msgs.msg import Temperature
from std_msgs.msg import Bool


class Thermostat(Node):
    def __init__(self):
        super().__init__('thermostat')
        self.declare_parameter('setpoint_c', 21.0)
        self.declare_parameter('band_c', 0.5)
        self.heating = False
        self.heaterPublisher = self.create_publisher(Bool, 'heater/on', 10)
        self.create_subscription(Temperature, 'room/temperature', self.temperatureCallback, 10)

    def temperatureCallback(self, msg):
        setpoint = self.get_parameter('setpoint_c').value
        band = self.get_parameter('band_c').value
        # switch on when too cold, off when warm enough, otherwise keep the last decision
        if msg.temperature < setpoint - band:
            self.heating = True
        elif msg.temperature > setpoint + band:
            self.heating = False
        command = Bool()
        command.data = self.heating
        self.heaterPublisher.publish(command)


def main(args=None):
    rclpy.init(args=args)
    thermostatNode = Thermostat()
    rclpy.spin(thermostatNode)
    thermostatNode.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
