# Thermometer node: simulates the room and publishes its temperature
import rclpy
from rclpy.node import Node
from sensor_msgs.msg import Temperature
from std_msgs.msg import Bool

from room_heat.physics import nextRoomTemperature


class Thermometer(Node):
    def __init__(self):
        super().__init__('thermometer')
        # parameters
        self.declare_parameter('outside_c', 5.0)
        self.declare_parameter('start_c', 17.0)
        self.declare_parameter('period_s', 0.25)
        self.outsideTemp = self.get_parameter('outside_c').value
        self.roomTemp = self.get_parameter('start_c').value
        self.period = self.get_parameter('period_s').value
        # the heater state closes the loop
        self.heaterOn = False
        self.create_subscription(Bool, 'heater/on', self.heaterCallback, 10)
        self.tempPublisher = self.create_publisher(Temperature, 'room/temperature', 10)
        self.create_timer(self.period, self.timerCallback)

    def heaterCallback(self, msg):
        self.heaterOn = msg.data

    def timerCallback(self):
        self.roomTemp = nextRoomTemperature(self.roomTemp, self.outsideTemp,
                                            self.heaterOn, self.period)
        reading = Temperature()
        reading.temperature = self.roomTemp
        reading.variance = 0.01
        self.tempPublisher.publish(reading)


def main(args=None):
    rclpy.init(args=args)
    thermometerNode = Thermometer()
    rclpy.spin(thermometerNode)
    thermometerNode.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
